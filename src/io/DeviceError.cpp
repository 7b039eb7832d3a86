#include "rp/io/DeviceError.hpp"

#include <cstdarg>
#include <cstdio>

namespace rp {

IoStatus DeviceError::set(IoStatus status, const char* format, ...) noexcept {
  status_ = status;
  va_list args;
  va_start(args, format);
  std::vsnprintf(message_.data(), message_.size(), format, args);
  va_end(args);
  return status;
}

}  // namespace rp
