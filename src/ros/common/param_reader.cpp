#include "sowing_robot/ros/common/param_reader.h"

#include "sowing_robot/ros/common/node_failure.h"

#include <ros/console.h>
#include <ros/param.h>
#include <ros/this_node.h>

#include <cstdio>
#include <cstdlib>

namespace sowing_robot {

template <typename T>
T ParamReader::read(const std::string& key, const T& def, const char* type_name) {
  const std::string full = nh_.resolveName(key);
  read_.insert(full);
  if (!nh_.hasParam(key)) return def;
  T value;
  if (!nh_.getParam(key, value)) {
    if (error_.empty()) error_ = "parameter " + full + " must be of type " + type_name;
    return def;
  }
  return value;
}

double ParamReader::get(const std::string& key, double def) { return read<double>(key, def, "double"); }
int ParamReader::get(const std::string& key, int def) {
  // roscpp's getParam(int&) truncates a double (2.5 -> 2) without a word: refuse anything but an int.
  XmlRpc::XmlRpcValue v;
  if (nh_.getParam(key, v) && v.getType() != XmlRpc::XmlRpcValue::TypeInt) {
    read_.insert(nh_.resolveName(key));
    if (error_.empty()) error_ = "parameter " + nh_.resolveName(key) + " must be of type int";
    return def;
  }
  return read<int>(key, def, "int");
}
bool ParamReader::get(const std::string& key, bool def) { return read<bool>(key, def, "bool"); }
std::string ParamReader::get(const std::string& key, const std::string& def) {
  return read<std::string>(key, def, "string");
}

core::ParamValue ParamReader::get(const std::string& key, const core::ParamValue& def) {
  if (const bool* b = std::get_if<bool>(&def)) return get(key, *b);
  if (const int* i = std::get_if<int>(&def)) return get(key, *i);
  if (const double* d = std::get_if<double>(&def)) return get(key, *d);
  return get(key, std::get<std::string>(def));
}

std::string ParamReader::unknownKeys() const {
  std::vector<std::string> names;
  ros::param::getParamNames(names);
  const std::string prefix = nh_.getNamespace() + "/";
  std::string unknown;
  for (const auto& n : names) {
    if (n.compare(0, prefix.size(), prefix) != 0 || read_.count(n)) continue;
    bool under_allowed = false;
    for (const auto& r : read_)
      if (!r.empty() && r.back() == '/' && n.compare(0, r.size(), r) == 0) under_allowed = true;
    if (!under_allowed) unknown += (unknown.empty() ? "" : ", ") + n;
  }
  return unknown.empty() ? "" : "unknown parameter(s): " + unknown;
}

void refuseToStart(const std::string& message) { throw badParameter(message); }

void exitProcess(int code) {
  ros::shutdown();
  std::fflush(stdout);
  std::fflush(stderr);
  std::_Exit(code);
}

}  // namespace sowing_robot
