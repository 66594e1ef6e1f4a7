#include "geometry/gmsh_session.hpp"

#include <gmsh.h>

namespace quadval::geometry {
namespace {
std::mutex g_gmsh_mutex;  // Gmsh's global state: one session at a time in this process
}  // namespace

GmshSession::GmshSession(bool verbose) : lock_(g_gmsh_mutex) {
  feholdexcept(&fenv_);
  gmsh::initialize(0, nullptr, /*readConfigFiles=*/false);
  gmsh::option::setNumber("General.Terminal", verbose ? 1 : 0);
  // Errors are logged and collected (take_errors) rather than thrown from inside Gmsh, so that
  // they become one InputError that names the user's file.
  gmsh::option::setNumber("General.AbortOnError", 0);
  gmsh::logger::start();
}

GmshSession::~GmshSession() {
  try {
    gmsh::logger::stop();
    gmsh::finalize();
  } catch (...) {  // a destructor must not throw; Gmsh has nothing left to tell us here
  }
  feclearexcept(FE_ALL_EXCEPT);
  fesetenv(&fenv_);
}

std::vector<std::string> GmshSession::take_messages() {
  std::vector<std::string> log;
  gmsh::logger::get(log);
  gmsh::logger::stop();  // stop + start empties the logger's buffer
  gmsh::logger::start();
  return log;
}

std::vector<std::string> GmshSession::take_errors() {
  std::vector<std::string> errors;
  for (const std::string& m : take_messages()) {
    static const std::string kPrefix = "Error: ";
    if (m.compare(0, kPrefix.size(), kPrefix) == 0) errors.push_back(m.substr(kPrefix.size()));
  }
  return errors;
}

}  // namespace quadval::geometry
