// Every parameter table of the package by the namespace it is read from, and what follows from them:
// docs/parameters.md and the comments of config/*.yaml. `param_docs` writes both; test_param_docs
// fails when either is out of step with the tables (or a YAML key is no parameter, or out of range).
#pragma once

#include <string>
#include <vector>

#include "sowing_robot/core/common/param_table.h"

namespace sowing_robot {
namespace core {

struct CatalogSection {
  std::string ns;       ///< where the keys live: "plant_sim", "run", "reference_generator", ...
  std::string summary;  ///< one line
  std::vector<ParamInfo> params;
  std::vector<std::string> lists;  ///< keys holding lists, documented apart (obstacles, gains)
};

/// Every node namespace with its parameters, in the order docs/parameters.md lists them; and the coverage
/// planner's table (coverage_planner, before any node reads it).
const std::vector<CatalogSection>& parameterCatalog();

/// The whole of docs/parameters.md.
std::string parametersMarkdown();

/// The comment a YAML line for `info` carries: "<meaning> [unit] (range, default D)".
std::string yamlComment(const ParamInfo& info);

/// One config/*.yaml file with every parameter line's comment rewritten from the catalogue (the value
/// kept). `problems` gets one line per key that is no parameter of its namespace, or whose value is out
/// of range. Lines that are not parameters (comments, namespaces, lists) are kept as they are.
std::string syncYamlComments(const std::string& text, const std::string& file, std::vector<std::string>& problems);

}  // namespace core
}  // namespace sowing_robot
