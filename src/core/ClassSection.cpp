// The class of an object under construction (rp/core/ClassSection.hpp).
#include "rp/core/ClassSection.hpp"

namespace rp {

namespace {
// The ClassSections alive in this thread, innermost first (temporaries end in reverse order).
thread_local ClassSection* innermost = nullptr;
}  // namespace

ClassSection::ClassSection(const std::string& name, const char* className) noexcept
    : name_(name), className_(className), outer_(innermost) {
  innermost = this;
}

ClassSection::~ClassSection() {
  if (innermost == this) {
    innermost = outer_;
    return;
  }
  for (ClassSection* s = innermost; s != nullptr; s = s->outer_)  // not innermost: unlink it
    if (s->outer_ == this) {
      s->outer_ = outer_;
      return;
    }
}

const char* ClassSection::claim() noexcept {
  const char* className = nullptr;
  for (ClassSection* s = innermost; s != nullptr && !s->claimed_; s = s->outer_) {
    s->claimed_ = true;
    className = s->className_;  // the outermost unclaimed one: the most derived class's
  }
  return className;
}

}  // namespace rp
