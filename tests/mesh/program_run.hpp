#pragma once
// Running one of the project's programs from a test: exit status and the
// combined stdout/stderr (written to dir/log.txt).
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace icd::test {

struct ProgramRun {
  int status = -1;  ///< exit status, -1 when the program did not exit normally
  std::string output;
};

inline ProgramRun run_program(const std::string& program, const std::string& args,
                              const std::filesystem::path& dir) {
  const std::filesystem::path log = dir / "log.txt";
  const std::string cmd = program + " " + args + " > " + log.string() + " 2>&1";
  const int raw = std::system(cmd.c_str());
  ProgramRun r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  std::ifstream in(log);
  std::stringstream ss;
  ss << in.rdbuf();
  r.output = ss.str();
  return r;
}

}  // namespace icd::test
