// param_docs: what follows from the parameter tables, written out. Usage: kUsage below (--help).
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

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
  sowing_robot::cli::exitOnHelp(argc, argv, kUsage);
  if (argc >= 2 && std::strcmp(argv[1], "--markdown") == 0) {
    std::cout << parametersMarkdown();
    return 0;
  }
  if (argc >= 3 && std::strcmp(argv[1], "--sync") == 0) {
    int rc = 0;
    for (int i = 2; i < argc; ++i) {
      std::ifstream in(argv[i]);
      if (!in) {
        std::fprintf(stderr, "param_docs: cannot read %s\n", argv[i]);
        return 2;
      }
      std::stringstream text;
      text << in.rdbuf();
      std::vector<std::string> problems;
      const std::string synced = syncYamlComments(text.str(), argv[i], problems);
      for (const auto& p : problems) std::fprintf(stderr, "param_docs: %s\n", p.c_str());
      if (!problems.empty()) rc = 1;
      if (synced != text.str()) {
        std::ofstream(argv[i]) << synced;
        std::printf("param_docs: rewrote %s\n", argv[i]);
      }
    }
    return rc;
  }
  if (argc >= 2 && argv[1][0] == '-' && std::strcmp(argv[1], "--sync") != 0)
    return sowing_robot::cli::unknownOption("param_docs", argv[1]);
  std::fprintf(stderr, "param_docs: %s (see param_docs --help)\n",
               argc < 2 ? "--markdown or --sync FILE.yaml... is needed" : "--sync needs FILE.yaml...");
  return 2;
}
