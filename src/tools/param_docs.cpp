// param_docs: what follows from the parameter tables, written out. Usage: kUsage below (--help).
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "sowing_robot/cli/options.h"
#include "sowing_robot/cli/usage.h"
#include "sowing_robot/core/settings/param_catalog.h"

namespace {
const char* const kUsage =
    "usage: param_docs --markdown | --sync FILE.yaml... | --help\n"
    "What follows from the parameter tables, written out.\n\n"
    "Options:\n"
    "  --markdown           docs/parameters.md on stdout\n"
    "  --sync FILE.yaml...  rewrite each file's parameter comments from the tables (values kept); exit 1 (with\n"
    "                       one line each) when a YAML key is no parameter or its value is out of range\n"
    "  -h, --help           this text\n";
}  // namespace

int main(int argc, char** argv) {
  using namespace sowing_robot::core;
  namespace cli = sowing_robot::cli;
  cli::exitOnHelp(argc, argv, kUsage);
  bool markdown = false;
  std::vector<std::string> files, stray;  // stray: arguments before any option (read as a --sync without files)
  cli::po::options_description options;
  options.add_options()("markdown", cli::po::bool_switch(&markdown))("sync", cli::po::value(&files)->multitoken())(
      "stray", cli::po::value(&stray));
  cli::Parse parse{"param_docs", options, {}, [](const std::string&) {
                     return "--sync needs FILE.yaml... (see param_docs --help)";
                   }};
  parse.positional.add("stray", -1);
  cli::po::variables_map vm;
  std::string error = cli::parseOptions(argc, argv, parse, vm);
  if (error.empty() && !markdown && files.empty())
    error = stray.empty() ? "--markdown or --sync FILE.yaml... is needed (see param_docs --help)"
                          : "--sync needs FILE.yaml... (see param_docs --help)";
  if (!error.empty()) {
    std::fprintf(stderr, "param_docs: %s\n", error.c_str());
    return cli::kUsageExit;
  }
  if (markdown) {
    std::cout << parametersMarkdown();
    return 0;
  }
  int rc = 0;
  for (const std::string& file : files) {
    std::ifstream in(file);
    if (!in) {
      std::fprintf(stderr, "param_docs: cannot read %s\n", file.c_str());
      return 2;
    }
    std::stringstream text;
    text << in.rdbuf();
    std::vector<std::string> problems;
    const std::string synced = syncYamlComments(text.str(), file, problems);
    for (const auto& p : problems) std::fprintf(stderr, "param_docs: %s\n", p.c_str());
    if (!problems.empty()) rc = 1;
    if (synced != text.str()) {
      std::ofstream(file) << synced;
      std::printf("param_docs: rewrote %s\n", file.c_str());
    }
  }
  return rc;
}
