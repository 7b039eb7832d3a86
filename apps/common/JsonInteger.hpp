// An integer field of a GUI message checked on its full 64-bit value (rp-jointmove,
// rp-teachpendant): nlohmann::json's get<int>() keeps the low 32 bits, so 4294967297 would pass a
// range check as 1.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>

namespace rp::apps {

/// Whether `v` is a JSON integer (signed or unsigned) within [lo, hi].
inline bool integerIn(const nlohmann::json& v, std::int64_t lo, std::int64_t hi) {
  if (v.is_number_unsigned()) return hi >= 0 && v.get<std::uint64_t>() <= static_cast<std::uint64_t>(hi) &&
                                     static_cast<std::int64_t>(v.get<std::uint64_t>()) >= lo;
  if (!v.is_number_integer()) return false;
  const std::int64_t x = v.get<std::int64_t>();
  return x >= lo && x <= hi;
}

}  // namespace rp::apps
