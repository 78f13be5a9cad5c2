// sowing_robot._bag: reads the topics of a sowing_robot recording into columns (NumPy arrays) with
// rosbag's C++ API. rosbag's Python reader spends ~30 us per message in genpy; a 110 s run of the default
// field has 660 k messages, so analyze_bag reads bags here (~1 us per message) and keeps only columns.
// Private to sowing_robot.analyze_bag (bag.py), which turns the exceptions below into one-line errors.
//
//   r = Reader(path)              opens the bag (rosbag::Bag, read mode); raises BagUnindexed, BagFormatError, ...
//   r.topics()                    [(topic, datatype)] of every connection
//   r.start_time, r.end_time      the bag's span (ros::Time::toSec), 0 for an empty bag
//   r.read({topic: datatype})     {topic: Series dict}; datatype one of KNOWN_TYPES
//   r.close()
//   write_csv(path, names, columns)   columns (equal-length float64/int64/bool arrays or lists of str) as CSV
// A series dict: "received" (messages, repeats included), "stamp_ns" (int64), "t" (toSec of the stamp),
// one float64 array per numeric field ("pose.pose.position.x", ...), bool arrays, lists for strings.
// Rows are de-duplicated by header.stamp (the first received kept) and sorted by stamp, as run_monitor
// sees them. Marker arrays have no stamp: only "received" and "markers", the markers of the last message.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <visualization_msgs/MarkerArray.h>

#include "sowing_robot/DesiredVelocity.h"
#include "sowing_robot/ReferenceState.h"
#include "sowing_robot/Seed.h"
#include "sowing_robot/TorqueControllerState.h"
#include "sowing_robot/TrackingError.h"
#include "sowing_robot/WheelTorque.h"

namespace py = pybind11;

namespace {

/// Columns of one topic in receive order, before de-duplication.
struct Columns {
  std::vector<std::int64_t> stamp_ns;
  std::vector<double> t;
  std::vector<std::string> real_names, bool_names, string_names;
  std::vector<std::vector<double>> reals;
  std::vector<std::vector<bool>> bools;
  std::vector<std::vector<std::string>> strings;
  std::size_t received = 0;

  void reserve(std::size_t n) {
    stamp_ns.reserve(n);
    t.reserve(n);
    for (auto& v : reals) v.reserve(n);
    for (auto& v : bools) v.reserve(n);
    for (auto& v : strings) v.reserve(n);
  }
  void stamp(const ros::Time& s) {
    stamp_ns.push_back(static_cast<std::int64_t>(s.toNSec()));
    t.push_back(s.toSec());
  }
};

/// Appends one message's fields; the column names are given once per type.
template <class M>
struct Extractor {
  std::vector<std::string> reals, bools, strings;
  std::function<void(const M&, Columns&)> add;
};

#define R(expr) c.reals[i++].push_back(expr)
Extractor<sowing_robot::TrackingError> trackingError() {
  return {{"x", "y", "theta", "xe", "ye", "thetae"}, {}, {}, [](const sowing_robot::TrackingError& m, Columns& c) {
            std::size_t i = 0;
            R(m.x);
            R(m.y);
            R(m.theta);
            R(m.xe);
            R(m.ye);
            R(m.thetae);
          }};
}
Extractor<nav_msgs::Odometry> odometry() {
  return {{"pose.pose.position.x", "pose.pose.position.y", "pose.pose.position.z", "pose.pose.orientation.x",
           "pose.pose.orientation.y", "pose.pose.orientation.z", "pose.pose.orientation.w", "twist.twist.linear.x",
           "twist.twist.linear.y", "twist.twist.linear.z", "twist.twist.angular.x", "twist.twist.angular.y",
           "twist.twist.angular.z"},
          {},
          {},
          [](const nav_msgs::Odometry& m, Columns& c) {
            std::size_t i = 0;
            const auto& p = m.pose.pose;
            const auto& v = m.twist.twist;
            R(p.position.x);
            R(p.position.y);
            R(p.position.z);
            R(p.orientation.x);
            R(p.orientation.y);
            R(p.orientation.z);
            R(p.orientation.w);
            R(v.linear.x);
            R(v.linear.y);
            R(v.linear.z);
            R(v.angular.x);
            R(v.angular.y);
            R(v.angular.z);
          }};
}
Extractor<sowing_robot::ReferenceState> referenceState() {
  return {{"x", "y", "theta", "v", "omega", "v_dot", "omega_dot"},
          {"tool_down"},
          {},
          [](const sowing_robot::ReferenceState& m, Columns& c) {
            std::size_t i = 0;
            R(m.x);
            R(m.y);
            R(m.theta);
            R(m.v);
            R(m.omega);
            R(m.v_dot);
            R(m.omega_dot);
            c.bools[0].push_back(m.tool_down);
          }};
}
Extractor<sowing_robot::Seed> seed() {
  return {{"position.x", "position.y", "believed.x", "believed.y", "row", "depth"},
          {"detour"},
          {},
          [](const sowing_robot::Seed& m, Columns& c) {
            std::size_t i = 0;
            R(m.position.x);
            R(m.position.y);
            R(m.believed.x);
            R(m.believed.y);
            R(m.row);
            R(m.depth);
            c.bools[0].push_back(m.detour);
          }};
}
Extractor<sowing_robot::DesiredVelocity> desiredVelocity() {
  return {{"v", "omega", "v_dot", "omega_dot"}, {}, {}, [](const sowing_robot::DesiredVelocity& m, Columns& c) {
            std::size_t i = 0;
            R(m.v);
            R(m.omega);
            R(m.v_dot);
            R(m.omega_dot);
          }};
}
Extractor<sowing_robot::WheelTorque> wheelTorque() {
  return {{"right", "left"}, {}, {}, [](const sowing_robot::WheelTorque& m, Columns& c) {
            std::size_t i = 0;
            R(m.right);
            R(m.left);
          }};
}
Extractor<sowing_robot::TorqueControllerState> torqueControllerState() {
  return {{"e_v", "e_omega", "s_v", "s_omega", "m0_hat", "i0_hat", "u1", "u2"},
          {"saturated"},
          {"mode"},
          [](const sowing_robot::TorqueControllerState& m, Columns& c) {
            std::size_t i = 0;
            R(m.e_v);
            R(m.e_omega);
            R(m.s_v);
            R(m.s_omega);
            R(m.m0_hat);
            R(m.i0_hat);
            R(m.u1);
            R(m.u2);
            c.bools[0].push_back(m.saturated);
            c.strings[0].push_back(m.mode);
          }};
}
#undef R

py::dict markerToDict(const visualization_msgs::Marker& mk) {
  py::dict d;
  d["type"] = mk.type;
  d["action"] = mk.action;
  d["x"] = mk.pose.position.x;
  d["y"] = mk.pose.position.y;
  d["scale_x"] = mk.scale.x;
  d["scale_y"] = mk.scale.y;
  py::list points;
  for (const auto& p : mk.points) points.append(py::make_tuple(p.x, p.y));
  d["points"] = points;
  return d;
}

class DeserializationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A message of the expected type name with another definition (md5), e.g. recorded before a field was added.
class DefinitionMismatch : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One topic being read: its columns and how to fill them from a message.
class TopicReader {
 public:
  virtual ~TopicReader() = default;
  /// n messages are coming (growing the columns one doubling at a time cost page faults).
  virtual void reserve(std::size_t /*n*/) {}
  virtual void add(const rosbag::MessageInstance& m) = 0;
  virtual py::dict finish() = 0;
};

template <class M>
class TypedReader : public TopicReader {
 public:
  explicit TypedReader(Extractor<M> e) : e_(std::move(e)) {
    c_.real_names = e_.reals;
    c_.bool_names = e_.bools;
    c_.string_names = e_.strings;
    c_.reals.resize(e_.reals.size());
    c_.bools.resize(e_.bools.size());
    c_.strings.resize(e_.strings.size());
  }
  void reserve(std::size_t n) override { c_.reserve(n); }
  void add(const rosbag::MessageInstance& m) override {
    const auto msg = instantiate<M>(m);
    ++c_.received;
    c_.stamp(msg->header.stamp);
    e_.add(*msg, c_);
  }
  py::dict finish() override {
    // Unique stamps, the first received kept, in stamp order: a stable sort by stamp, then the first of each run.
    std::vector<std::size_t> order(c_.stamp_ns.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [this](std::size_t a, std::size_t b) { return c_.stamp_ns[a] < c_.stamp_ns[b]; });
    std::vector<std::size_t> keep;
    keep.reserve(order.size());
    for (std::size_t k = 0; k < order.size(); ++k)
      if (k == 0 || c_.stamp_ns[order[k]] != c_.stamp_ns[order[k - 1]]) keep.push_back(order[k]);
    py::dict d;
    d["received"] = c_.received;
    d["stamp_ns"] = pick<std::int64_t>(c_.stamp_ns, keep);
    d["t"] = pick<double>(c_.t, keep);
    for (std::size_t j = 0; j < c_.reals.size(); ++j) d[c_.real_names[j].c_str()] = pick<double>(c_.reals[j], keep);
    for (std::size_t j = 0; j < c_.bools.size(); ++j) {
      py::array_t<bool> a(static_cast<py::ssize_t>(keep.size()));
      auto* p = a.mutable_data();
      for (std::size_t k = 0; k < keep.size(); ++k) p[k] = c_.bools[j][keep[k]];
      d[c_.bool_names[j].c_str()] = a;
    }
    for (std::size_t j = 0; j < c_.strings.size(); ++j) {
      py::list l;
      for (const auto k : keep) l.append(c_.strings[j][k]);
      d[c_.string_names[j].c_str()] = l;
    }
    return d;
  }

  template <class T>
  static boost::shared_ptr<T> instantiate(const rosbag::MessageInstance& m) {
    boost::shared_ptr<T> msg;
    try {
      msg = m.instantiate<T>();
    } catch (const ros::Exception& e) {  // StreamOverrunException and friends: a corrupt message
      throw DeserializationError(m.getTopic() + ": " + e.what());
    }
    if (!msg)
      throw DefinitionMismatch(m.getTopic() + ": " + m.getDataType() + " recorded with another definition (md5 " +
                               m.getMD5Sum() + ", this build's " + ros::message_traits::md5sum<T>() + ")");
    return msg;
  }

 private:
  template <class T>
  static py::array_t<T> pick(const std::vector<T>& v, const std::vector<std::size_t>& keep) {
    py::array_t<T> a(static_cast<py::ssize_t>(keep.size()));
    T* p = a.mutable_data();
    for (std::size_t k = 0; k < keep.size(); ++k) p[k] = v[keep[k]];
    return a;
  }

  Extractor<M> e_;
  Columns c_;
};

/// Marker topics: no stamp to sort by; the obstacles are those of the last message.
class MarkerReader : public TopicReader {
 public:
  void add(const rosbag::MessageInstance& m) override {
    ++received_;
    if (m.isType<visualization_msgs::MarkerArray>()) {
      last_ = TypedReader<sowing_robot::WheelTorque>::instantiate<visualization_msgs::MarkerArray>(m)->markers;
    } else {
      last_ = {*TypedReader<sowing_robot::WheelTorque>::instantiate<visualization_msgs::Marker>(m)};
    }
  }
  py::dict finish() override {
    py::dict d;
    d["received"] = received_;
    py::list l;
    for (const auto& mk : last_) l.append(markerToDict(mk));
    d["markers"] = l;
    return d;
  }

 private:
  std::size_t received_ = 0;
  std::vector<visualization_msgs::Marker> last_;
};

std::unique_ptr<TopicReader> readerFor(const std::string& type) {
  if (type == "sowing_robot/TrackingError")
    return std::make_unique<TypedReader<sowing_robot::TrackingError>>(trackingError());
  if (type == "nav_msgs/Odometry") return std::make_unique<TypedReader<nav_msgs::Odometry>>(odometry());
  if (type == "sowing_robot/ReferenceState")
    return std::make_unique<TypedReader<sowing_robot::ReferenceState>>(referenceState());
  if (type == "sowing_robot/Seed") return std::make_unique<TypedReader<sowing_robot::Seed>>(seed());
  if (type == "sowing_robot/DesiredVelocity")
    return std::make_unique<TypedReader<sowing_robot::DesiredVelocity>>(desiredVelocity());
  if (type == "sowing_robot/WheelTorque")
    return std::make_unique<TypedReader<sowing_robot::WheelTorque>>(wheelTorque());
  if (type == "sowing_robot/TorqueControllerState")
    return std::make_unique<TypedReader<sowing_robot::TorqueControllerState>>(torqueControllerState());
  if (type == "visualization_msgs/MarkerArray" || type == "visualization_msgs/Marker")
    return std::make_unique<MarkerReader>();
  throw py::value_error("no reader for message type '" + type + "'");
}

class Reader {
 public:
  explicit Reader(const std::string& path) { bag_.open(path, rosbag::bagmode::Read); }

  std::vector<std::pair<std::string, std::string>> topics() {
    rosbag::View view(bag_);
    std::vector<std::pair<std::string, std::string>> out;
    for (const rosbag::ConnectionInfo* c : view.getConnections()) out.emplace_back(c->topic, c->datatype);
    return out;
  }
  double startTime() {
    rosbag::View view(bag_);
    return view.size() ? view.getBeginTime().toSec() : 0.0;
  }
  double endTime() {
    rosbag::View view(bag_);
    return view.size() ? view.getEndTime().toSec() : 0.0;
  }

  py::dict read(const std::map<std::string, std::string>& wanted) {
    std::map<std::string, std::unique_ptr<TopicReader>> readers;
    std::vector<std::string> names;
    for (const auto& [topic, type] : wanted) {
      readers[topic] = readerFor(type);
      names.push_back(topic);
    }
    {
      py::gil_scoped_release no_gil;
      for (auto& [topic, r] : readers) r->reserve(rosbag::View(bag_, rosbag::TopicQuery(topic)).size());
      rosbag::View view(bag_, rosbag::TopicQuery(names));
      for (const rosbag::MessageInstance& m : view) readers.at(m.getTopic())->add(m);
    }
    py::dict out;
    for (auto& [topic, r] : readers) out[topic.c_str()] = r->finish();
    return out;
  }

  void close() { bag_.close(); }

 private:
  rosbag::Bag bag_;
};

/// One CSV column: a NumPy array (kept alive here) or strings.
struct CsvColumn {
  char kind = 0;  // 'f' float64, 'i' int64, 'b' bool, 's' strings
  py::array array;
  std::vector<std::string> strings;
  std::size_t size() const { return kind == 's' ? strings.size() : static_cast<std::size_t>(array.size()); }
};

void appendDouble(std::string& out, double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);  // shortest form that reads back to the same double
  out.append(buf, r.ptr);
  if (std::all_of(buf, r.ptr, [](char c) { return (c >= '0' && c <= '9') || c == '-'; })) out += ".0";  // a float
}

void appendString(std::string& out, const std::string& v) {
  if (v.find_first_of(",\"\n\r") == std::string::npos) {
    out += v;
    return;
  }
  out += '"';
  for (char c : v) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  out += '"';
}

/// The rows of writeCsv, without the GIL; returns 0 or an errno.
int writeRows(const std::string& path, const std::vector<std::string>& names, const std::vector<CsvColumn>& cols,
              std::size_t rows) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return errno;
  std::string out;
  for (std::size_t j = 0; j < names.size(); ++j) {
    if (j) out += ',';
    appendString(out, names[j]);
  }
  out += '\n';
  bool ok = true;
  for (std::size_t i = 0; i < rows && ok; ++i) {
    for (std::size_t j = 0; j < cols.size(); ++j) {
      if (j) out += ',';
      const CsvColumn& c = cols[j];
      switch (c.kind) {
        case 'f': appendDouble(out, static_cast<const double*>(c.array.data())[i]); break;
        case 'i': {
          char buf[32];
          out.append(buf,
                     std::to_chars(buf, buf + sizeof buf, static_cast<const std::int64_t*>(c.array.data())[i]).ptr);
          break;
        }
        case 'b': out += static_cast<const bool*>(c.array.data())[i] ? "True" : "False"; break;
        default: appendString(out, c.strings[i]);
      }
    }
    out += '\n';
    if (out.size() > (1u << 20)) {
      ok = std::fwrite(out.data(), 1, out.size(), f) == out.size();
      out.clear();
    }
  }
  ok = ok && std::fwrite(out.data(), 1, out.size(), f) == out.size();
  ok = (std::fclose(f) == 0) && ok;
  return ok ? 0 : (errno ? errno : EIO);
}

/// Columns as CSV (a header of names, a row per index): floats in the shortest form that reads back
/// exactly (std::to_chars; Python's repr takes ~10x longer for the 660 k rows of a field run), bools True/False.
void writeCsv(const std::string& path, const std::vector<std::string>& names, const std::vector<py::object>& columns) {
  if (names.size() != columns.size()) throw py::value_error("one name per column");
  std::vector<CsvColumn> cols(columns.size());
  for (std::size_t j = 0; j < columns.size(); ++j) {
    CsvColumn& c = cols[j];
    if (py::isinstance<py::array>(columns[j])) {
      c.array = columns[j].cast<py::array>();
      if (c.array.ndim() != 1) throw py::value_error("column '" + names[j] + "' is not 1-D");
      const char k = c.array.dtype().kind();
      if (k == 'f')
        c.array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(c.array);
      else if (k == 'i' || k == 'u')
        c.array = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(c.array);
      else if (k == 'b')
        c.array = py::array_t<bool, py::array::c_style | py::array::forcecast>::ensure(c.array);
      else
        throw py::value_error("column '" + names[j] + "': unsupported dtype");
      c.kind = k == 'u' ? 'i' : k;
    } else {
      c.kind = 's';
      for (const auto& v : columns[j]) c.strings.push_back(py::str(v));
    }
    if (c.size() != cols[0].size()) throw py::value_error("column '" + names[j] + "' has another length");
  }
  const std::size_t rows = cols.empty() ? 0 : cols[0].size();
  int error = 0;
  {
    py::gil_scoped_release no_gil;
    error = writeRows(path, names, cols, rows);
  }
  if (error) {
    errno = error;
    PyErr_SetFromErrnoWithFilename(PyExc_OSError, path.c_str());
    throw py::error_already_set();
  }
}

}  // namespace

PYBIND11_MODULE(_bag, m) {
  m.doc() = "Columns of sowing_robot bags, read with rosbag's C++ API (private to sowing_robot.analyze_bag).";
  m.attr("KNOWN_TYPES") =
      py::make_tuple("sowing_robot/TrackingError", "nav_msgs/Odometry", "sowing_robot/ReferenceState",
                     "sowing_robot/DesiredVelocity", "sowing_robot/WheelTorque", "sowing_robot/TorqueControllerState",
                     "visualization_msgs/MarkerArray", "visualization_msgs/Marker", "sowing_robot/Seed");
  static py::exception<rosbag::BagException> bag_error(m, "BagError");
  static py::exception<rosbag::BagUnindexedException> unindexed(m, "BagUnindexed", bag_error.ptr());
  static py::exception<rosbag::BagFormatException> format_error(m, "BagFormatError", bag_error.ptr());
  static py::exception<rosbag::BagIOException> io_error(m, "BagIOError", bag_error.ptr());
  static py::exception<DeserializationError> deser(m, "DeserializationError", bag_error.ptr());
  static py::exception<DefinitionMismatch> mismatch(m, "DefinitionMismatch", bag_error.ptr());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const rosbag::BagUnindexedException& e) {
      unindexed(e.what());
    } catch (const rosbag::BagFormatException& e) {
      format_error(e.what());
    } catch (const rosbag::BagIOException& e) {
      io_error(e.what());
    } catch (const DeserializationError& e) {
      deser(e.what());
    } catch (const DefinitionMismatch& e) {
      mismatch(e.what());
    } catch (const rosbag::BagException& e) {
      bag_error(e.what());
    } catch (const ros::Exception& e) {  // serialization errors while reading the index or a chunk
      deser(e.what());
    }
  });
  py::class_<Reader>(m, "Reader")
      .def(py::init<const std::string&>(), py::arg("path"))
      .def("topics", &Reader::topics)
      .def_property_readonly("start_time", &Reader::startTime)
      .def_property_readonly("end_time", &Reader::endTime)
      .def("read", &Reader::read, py::arg("wanted"))
      .def("close", &Reader::close);
  m.def("write_csv", &writeCsv, py::arg("path"), py::arg("names"), py::arg("columns"),
        "Equal-length columns (float64/int64/bool arrays, lists of str) as a CSV file; OSError on failure.");
}
