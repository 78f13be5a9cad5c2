#include "sowing_robot/core/evaluation/checkpoint.h"

#include <cstdio>
#include <fstream>
#include <iterator>
#include <sstream>

namespace sowing_robot {
namespace core {

namespace {
constexpr int kVersion = 1;
}

std::uint64_t fnv1a64(const std::string& bytes) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return h;
}

std::string hex64(std::uint64_t v) {
  char b[20];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(v));
  return b;
}

std::string writeCheckpoint(const std::string& path, const std::string& kind, std::uint64_t fingerprint,
                            const std::string& body) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) return "cannot open " + tmp + " for writing";
    f << "sowing_robot_checkpoint " << kVersion << " " << kind << "\n"
      << "fingerprint " << hex64(fingerprint) << "\n"
      << "body " << body.size() << " fnv1a64 " << hex64(fnv1a64(body)) << "\n"
      << body;
    f.flush();
    if (!f) return "cannot write " + tmp;
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) return "cannot rename " + tmp + " to " + path;
  return "";
}

std::string readCheckpoint(const std::string& path, const std::string& kind, std::uint64_t fingerprint,
                           std::string& body) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return "cannot read checkpoint " + path;
  const std::string all((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  const std::string bad = "checkpoint " + path + ": ";
  std::istringstream in(all);
  std::string magic, k, word, fp, sum;
  int version = 0;
  if (!(in >> magic >> version >> k) || magic != "sowing_robot_checkpoint") return bad + "not a checkpoint file";
  if (version != kVersion)
    return bad + "version " + std::to_string(version) + ", this build reads version " + std::to_string(kVersion);
  if (k != kind) return bad + "holds a '" + k + "' state, not a '" + kind + "' one";
  if (!(in >> word >> fp) || word != "fingerprint") return bad + "no fingerprint line (damaged)";
  if (fp != hex64(fingerprint))
    return bad + "written for another setup (fingerprint " + fp + ", this run's " + hex64(fingerprint) +
           "): other config, scenario or PSO parameters; remove it or drop --resume";
  unsigned long long size = 0;
  if (!(in >> word >> size) || word != "body" || !(in >> word >> sum) || word != "fnv1a64")
    return bad + "no body line (damaged)";
  in.get();  // the newline ending the header
  const auto at = in.tellg();
  if (at < 0) return bad + "truncated";
  const std::size_t start = static_cast<std::size_t>(at);
  if (all.size() - start != size)
    return bad + "body has " + std::to_string(all.size() - start) + " bytes, the header says " + std::to_string(size) +
           " (truncated or damaged)";
  body = all.substr(start);
  if (hex64(fnv1a64(body)) != sum) return bad + "checksum mismatch (damaged)";
  return "";
}

}  // namespace core
}  // namespace sowing_robot
