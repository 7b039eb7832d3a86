#pragma once
/// @file
/// The type database: every class that rp.cfg can name (paper section 3.6, footnote 1).

#include <functional>
#include <memory>
#include <string>
#include <typeindex>
#include <typeinfo>
#include <vector>

#include "rp/core/ClassSection.hpp"
#include "rp/core/Configuration.hpp"

namespace rp {

class RoboticObject;

/// One registered class.
struct TypeInfo {
  std::string name;  ///< class name as written after `class` in rp.cfg
  std::function<RoboticObject*(const std::string&)> create;  ///< `new T(objectName)`
  std::function<void()> throwNullPointer;  ///< throws `static_cast<T*>(nullptr)`: tests derivation
  SettingSchema schema;  ///< settings the class accepts (from `T::declareSettings`)
  std::type_index type;  ///< the C++ type
};

/// The process-wide database of classes that can be created by name.
///
/// Register a class with one line next to its definition (in a .cpp file, the user's program or
/// a plugin library):
/// @code
/// RP_REGISTER_CLASS(Puma560);
/// @endcode
/// The class needs a constructor taking the object name (`explicit Puma560(const std::string&
/// name = "")`) and may declare its rp.cfg settings in a static
/// `declareSettings(SettingSchema&)` that first calls its base class's.
class TypeDatabase {
 public:
  /// The one database of the process.
  static TypeDatabase& instance();

  /// Registers class `T` under `name`.
  /// @tparam T  a class derived from RoboticObject with a constructor taking the object name
  /// @param[in] name  class name for rp.cfg
  /// @return true (so it can initialise a static variable)
  /// @throws std::logic_error if `name` is already registered
  /// Real-time safe: no.
  template <typename T>
  static bool registerClass(const std::string& name) {
    SettingSchema schema;
    T::declareSettings(schema);
    // The object is created knowing its class (see ClassSection): without a section of its own it
    // is configured from [name]. `className` lives in the database, which is never destroyed.
    instance().add(TypeInfo{name,
                            [className = name](const std::string& objectName) -> RoboticObject* {
                              const ClassSection section(objectName, className.c_str());
                              return new T(section);
                            },
                            [] { throw static_cast<T*>(nullptr); }, std::move(schema), std::type_index(typeid(T))});
    return true;
  }
  /// Adds a class description.
  /// @param[in] info  the class
  /// @throws std::logic_error if its name is already registered
  void add(TypeInfo info);
  /// The class registered as `name`, or nullptr.
  /// @param[in] name  class name
  const TypeInfo* find(const std::string& name) const;
  /// The class registered for the C++ type `type`, or nullptr.
  /// @param[in] type  a C++ type
  const TypeInfo* find(const std::type_index& type) const;
  /// Whether class `name` is registered.
  /// @param[in] name  class name
  bool contains(const std::string& name) const { return find(name) != nullptr; }
  /// All registered class names, sorted.
  std::vector<std::string> classNames() const;
  /// The registered names, comma separated, for error messages.
  std::string knownNames() const;
  /// Whether registered class `name` is `Base` or derived from it.
  /// @tparam Base  a class
  /// @param[in] name  registered class name
  /// @return false for unknown names
  template <typename Base>
  bool isDerivedFrom(const std::string& name) const {
    const TypeInfo* info = find(name);
    if (!info) return false;
    try {
      info->throwNullPointer();
    } catch (Base*) {
      return true;
    } catch (...) {
      return false;
    }
    return false;
  }

 private:
  TypeDatabase() = default;
  std::vector<std::unique_ptr<TypeInfo>> types_;
};

}  // namespace rp

/// @cond INTERNAL
#define RP_CONCAT_INNER_(a, b) a##b
#define RP_CONCAT_(a, b) RP_CONCAT_INNER_(a, b)
/// @endcond

/// Registers class `Class` in the type database under its own name (one line next to its
/// definition, at namespace scope in a .cpp file).
#define RP_REGISTER_CLASS(Class) RP_REGISTER_CLASS_AS(Class, #Class)

/// Registers C++ class `Class` under the name `name` (for templates or classes in namespaces).
#define RP_REGISTER_CLASS_AS(Class, name)                                                           \
  namespace {                                                                                       \
  [[maybe_unused]] const bool RP_CONCAT_(rpRegistered_, __COUNTER__) =                              \
      ::rp::TypeDatabase::registerClass<Class>(name);                                               \
  }                                                                                                 \
  static_assert(true, "")
