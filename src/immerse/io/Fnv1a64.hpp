#pragma once
// FNV-1a, 64 bit: the checksum of checkpoints (Checkpoint, ParallelCheckpoint). Its state is one number, so a hash
// over data spread across processes is computed by handing the state from one process to the next.
#include <cstddef>
#include <cstdint>
#include <string>

namespace immerse::io {

class Fnv1a64 {
 public:
  Fnv1a64() = default;
  explicit Fnv1a64(std::uint64_t state) : h_(state) {}
  void bytes(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h_ = (h_ ^ b[i]) * 0x100000001b3ull;
  }
  void u64(std::uint64_t v) { bytes(&v, sizeof v); }
  void text(const std::string& s) {
    u64(s.size());
    bytes(s.data(), s.size());
  }
  std::uint64_t value() const { return h_; }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ull;
};

}  // namespace immerse::io
