#pragma once
// One Gmsh API session (gmsh::initialize ... gmsh::finalize) as an RAII object. Gmsh keeps
// global state and is not thread-safe, so a session holds a process-wide lock for its whole
// life: a second session in another thread waits. Internal to src/geometry.

#include <cfenv>
#include <mutex>
#include <string>
#include <vector>

namespace quadval::geometry {

class GmshSession {
 public:
  /// Initialises Gmsh without reading the user's configuration files, sends its messages to
  /// the logger (and to the terminal only if `verbose`), and pauses the floating-point traps
  /// that debug test runs enable (Gmsh computes with inf internally).
  explicit GmshSession(bool verbose);
  ~GmshSession();
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;

  /// Gmsh's messages since the last call, e.g. "Error: ...", "Warning: ...".
  std::vector<std::string> take_messages();
  /// The "Error" messages since the last call, each without its "Error: " prefix.
  std::vector<std::string> take_errors();

 private:
  std::unique_lock<std::mutex> lock_;
  std::fenv_t fenv_{};
};

}  // namespace quadval::geometry
