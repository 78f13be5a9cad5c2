// param_docs: what follows from the parameter tables, written out.
//   param_docs --markdown            docs/parameters.md on stdout
//   param_docs --sync FILE.yaml...   rewrite each file's parameter comments from the tables (values kept)
// Exit 1 (with one line each) when a YAML key is no parameter or its value is out of range.
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "sowing_robot/core/settings/param_catalog.h"

int main(int argc, char** argv) {
  using namespace sowing_robot::core;
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
  std::fprintf(stderr, "usage: param_docs --markdown | --sync FILE.yaml...\n");
  return 2;
}
