// The command-line tools' options (src/tools), read by Boost.Program_options in one way: `--name VALUE` or
// `--name=VALUE`, switches, positional arguments; no abbreviated option names. A refusal is one line without the
// command's name (the tool prints "<cmd>: <line>" and exits 2, cli::kUsageExit):
//   unknown option '--x' (see <cmd> --help)
//   --x needs a value (see <cmd> --help)        (or the command's own wording, Parse::missing)
//   --x given more than once (see <cmd> --help)
// --help is answered before any of this (usage.h's exitOnHelp).
#pragma once

#include <boost/program_options.hpp>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace sowing_robot::cli {

namespace po = boost::program_options;

/// What a command declares.
struct Parse {
  const char* cmd;                                     ///< the command's name, for "(see <cmd> --help)"
  const po::options_description& options;              ///< the options, with their values' targets
  po::positional_options_description positional = {};  ///< the arguments without an option name, if any
  /// The line for an option given without its value; default "--x needs a value (see <cmd> --help)".
  std::function<std::string(const std::string& option)> missing = nullptr;
  /// Options that take this many values whatever they look like ("--start -1 -2 0": Boost would read "-2" as an
  /// option); declared multitoken. Fewer values at the end of the line are stored as given, for the tool to say
  /// which is missing.
  std::vector<std::pair<std::string, int>> fixed_arity = {};
};

/// Reads argv[1..argc) as `p` declares into `vm` (po::store, then po::notify: the targets are set); "" or the one
/// line why not. `order`, if given, receives the options' names (without "--") in the order given.
std::string parseOptions(int argc, const char* const* argv, const Parse& p, po::variables_map& vm,
                         std::vector<std::string>* order = nullptr);

}  // namespace sowing_robot::cli
