// --help and unknown options for the package's commands, one way for all of them:
// `--help` / `-h` prints the command's usage text (one string per command, used for --help only) to stdout
// and exits 0 before any work; an unknown option is one line on stderr,
//   <cmd>: unknown option '--x' (see <cmd> --help)
// and exit 2. Header-only, no ROS: the in-process programs and the ROS nodes include it alike.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace sowing_robot::cli {

constexpr int kUsageExit = 2;

inline bool isHelp(const char* arg) { return std::strcmp(arg, "--help") == 0 || std::strcmp(arg, "-h") == 0; }

/// Prints `usage` and exits 0 when an argument is --help or -h (the values of options included: a command
/// whose option takes "-h" as a value has none).
inline void exitOnHelp(int argc, char** argv, const char* usage) {
  for (int i = 1; i < argc; ++i)
    if (isHelp(argv[i])) {
      std::fputs(usage, stdout);
      std::exit(0);
    }
}

/// The one line for an option the command does not know; returns the exit code (2).
inline int unknownOption(const char* cmd, const std::string& option) {
  std::fprintf(stderr, "%s: unknown option '%s' (see %s --help)\n", cmd, option.c_str(), cmd);
  return kUsageExit;
}

/// A ROS node's usage text: its purpose (a string literal, lines ending in \n) and where its topics and
/// parameters are described.
#define SOWING_NODE_USAGE(name, purpose)                                                              \
  "usage: rosrun sowing_robot " name                                                                  \
  " [ROS arguments: topic:=other _param:=value __name:=NAME __ns:=NS ...]\n"                          \
  "       rosrun sowing_robot " name " --help\n\n" purpose                                            \
  "\nTopics: README.md, \"Nodes and topics\"; parameters (~name): docs/parameters.md, section `" name \
  "`.\n"                                                                                              \
  "Usually started by a launch file (roslaunch sowing_robot sim.launch); it needs a ROS master.\n"    \
  "\nOptions:\n  -h, --help   this text (no master needed)\n"

/// For a ROS node's main, before ros::init: --help prints `usage` (exit 0, no master needed); any other
/// argument that starts with '-' is refused (exit 2). ROS arguments (`name:=value`: remappings, `_param:=`,
/// `__name:=`, `__log:=` as roslaunch passes them) go through untouched.
inline void checkNodeArguments(int argc, char** argv, const char* cmd, const char* usage) {
  exitOnHelp(argc, argv, usage);
  for (int i = 1; i < argc; ++i)
    if (argv[i][0] == '-' && std::strstr(argv[i], ":=") == nullptr) std::exit(unknownOption(cmd, argv[i]));
}

}  // namespace sowing_robot::cli
