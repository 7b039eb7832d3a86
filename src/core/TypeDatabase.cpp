// The type database: classes creatable by name.
#include "rp/core/TypeDatabase.hpp"

#include <algorithm>
#include <mutex>
#include <stdexcept>

namespace rp {

namespace {
std::mutex& typeMutex() {
  static std::mutex m;
  return m;
}
}  // namespace

TypeDatabase& TypeDatabase::instance() {
  static TypeDatabase* db = new TypeDatabase;  // never destroyed: plugins and exit handlers use it
  return *db;
}

void TypeDatabase::add(TypeInfo info) {
  std::lock_guard<std::mutex> lock(typeMutex());
  for (const auto& t : types_)
    if (t->name == info.name) throw std::logic_error("TypeDatabase: class '" + info.name + "' is registered twice");
  types_.push_back(std::make_unique<TypeInfo>(std::move(info)));
}

const TypeInfo* TypeDatabase::find(const std::string& name) const {
  std::lock_guard<std::mutex> lock(typeMutex());
  for (const auto& t : types_)
    if (t->name == name) return t.get();
  return nullptr;
}

const TypeInfo* TypeDatabase::find(const std::type_index& type) const {
  std::lock_guard<std::mutex> lock(typeMutex());
  for (const auto& t : types_)
    if (t->type == type) return t.get();
  return nullptr;
}

std::vector<std::string> TypeDatabase::classNames() const {
  std::vector<std::string> names;
  {
    std::lock_guard<std::mutex> lock(typeMutex());
    for (const auto& t : types_) names.push_back(t->name);
  }
  std::sort(names.begin(), names.end());
  return names;
}

std::string TypeDatabase::knownNames() const {
  std::string out;
  for (const auto& n : classNames()) out += (out.empty() ? "" : ", ") + n;
  return out.empty() ? std::string("none") : out;
}

}  // namespace rp
