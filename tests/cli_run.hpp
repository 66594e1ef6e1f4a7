#pragma once
// Runs the built `quadval` (QUADVAL_CLI_PATH) with a command line and captures what a user
// would see: the exit code, standard output and standard error.
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace quadval::testing_cli {

struct CliRun {
  int code = -1;       ///< exit status (-1 if the process did not exit normally)
  std::string out;     ///< standard output
  std::string err;     ///< standard error
  std::string output;  ///< standard output followed by standard error
};

/// `args` is appended to the binary's path as shell words (quote paths with spaces).
inline CliRun run_cli(const std::string& args) {
  static std::atomic<int> counter{0};
  namespace fs = std::filesystem;
  const fs::path base = fs::temp_directory_path() /
                        ("quadval_cli_" + std::to_string(::getpid()) + "_" +
                         std::to_string(counter++));
  const fs::path out_file = base.string() + ".out", err_file = base.string() + ".err";
  const std::string cmd = std::string("'") + QUADVAL_CLI_PATH + "' " + args + " >'" +
                          out_file.string() + "' 2>'" + err_file.string() + "' </dev/null";
  const int status = std::system(cmd.c_str());
  auto slurp = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  CliRun r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out_file);
  r.err = slurp(err_file);
  r.output = r.out + r.err;
  std::error_code ignored;
  fs::remove(out_file, ignored);
  fs::remove(err_file, ignored);
  return r;
}

/// The whole content of a file (empty when it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace quadval::testing_cli
