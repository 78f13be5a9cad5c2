// Reads a node's private parameters once at start-up, remembers which keys were read, and reports the
// first problem (wrong type, unknown key) as one line. Range checks live in the core params' validate().
#pragma once

#include <ros/node_handle.h>

#include <set>
#include <string>

#include "sowing_robot/core/common/param_table.h"

namespace sowing_robot {

class ParamReader {
 public:
  explicit ParamReader(const ros::NodeHandle& nh) : nh_(nh) {}

  /// Value of `key` (relative to the handle) or `def` when absent; a value of the wrong type is an error.
  double get(const std::string& key, double def);
  int get(const std::string& key, int def);
  bool get(const std::string& key, bool def);
  std::string get(const std::string& key, const std::string& def);
  std::string get(const std::string& key, const char* def) { return get(key, std::string(def)); }
  /// The same, with the type taken from the default's (a parameter table's entry).
  core::ParamValue get(const std::string& key, const core::ParamValue& def);

  /// Mark a key (or a whole sub-namespace ending in '/') as known without reading it.
  void allow(const std::string& key) { read_.insert(nh_.getNamespace() + "/" + key); }

  /// Record a problem found by the caller (a range check); the first one is kept.
  void fail(const std::string& message) {
    if (error_.empty()) error_ = message;
  }
  /// First type error, or "" when every read succeeded.
  const std::string& error() const { return error_; }
  /// "" when every parameter under the handle's namespace was read, else one line listing the others
  /// (catches the typo that would silently leave a default in force).
  std::string unknownKeys() const;
  const ros::NodeHandle& handle() const { return nh_; }

 private:
  template <typename T>
  T read(const std::string& key, const T& def, const char* type_name);

  ros::NodeHandle nh_;
  std::set<std::string> read_;
  std::string error_;
};

/// The refusal to start that STYLE.md asks for: throws badParameter(message) (node_failure.h). The node's
/// main (or nodelet's onInit) logs it as "<node>: refusing to start: <message>" (logFailure) and exits 1
/// (a nodelet is not loaded); library code never ends the process.
[[noreturn]] void refuseToStart(const std::string& message);

/// For a node's main only: ends the process with `code` once its FATAL line has been logged:
/// ros::shutdown(), flush stdout and stderr, then std::_Exit. Not std::exit: its static destructors raced
/// roscpp's threads, which were still running, and now and then turned the exit code into an abort (seen
/// in CI).
[[noreturn]] void exitProcess(int code);

}  // namespace sowing_robot
