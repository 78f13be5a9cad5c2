// Checkpoint files: a text body behind a header that says what it is and lets a reader
// refuse a damaged, truncated or foreign file with one line instead of resuming from it.
//
//   sowing_robot_checkpoint 1 KIND
//   fingerprint HHHHHHHHHHHHHHHH      (FNV-1a 64 of what the run was started with: another setup -> refused)
//   body N fnv1a64 HHHHHHHHHHHHHHHH   (N bytes follow, with this checksum)
//   <body>
//
// Written to PATH.tmp and renamed over PATH, so PATH is always a whole checkpoint: a process killed at any
// point leaves the previous one or the new one, never half of one.
#pragma once

#include <cstdint>
#include <string>

namespace sowing_robot {
namespace core {

/// FNV-1a, 64 bits.
std::uint64_t fnv1a64(const std::string& bytes);
/// 16 lower-case hex digits.
std::string hex64(std::uint64_t v);

/// "" or one line naming the failure (cannot write, cannot rename).
std::string writeCheckpoint(const std::string& path, const std::string& kind, std::uint64_t fingerprint,
                            const std::string& body);

/// Reads PATH into body. "" or one line: cannot read, not a checkpoint, another version or kind, another
/// fingerprint (another setup), wrong size or checksum (damaged or truncated).
std::string readCheckpoint(const std::string& path, const std::string& kind, std::uint64_t fingerprint,
                           std::string& body);

}  // namespace core
}  // namespace sowing_robot
