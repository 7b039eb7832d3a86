#pragma once
/// @file
/// The class of an object under construction, for configuring an object that has no rp.cfg
/// section of its own from the section named after its class (`[Puma560]`).

#include <string>

namespace rp {

/// The object name a class's constructor passes on to its base class's constructor, together
/// with the name of the class. While the base constructors run, it tells the RoboticObject
/// constructor which class the object is: an object without a section of its own (an unnamed
/// one, such as the paper's `Puma560 puma;`, or a named one whose name has no section) is then
/// configured from the section named after its class, `[Puma560]`. A section named after the
/// object always wins over the class's.
///
/// A class that can be declared directly (not only created by name) passes it in its
/// constructor's base-class call:
/// @code
/// Puma560::Puma560(const std::string& name)
///     : DefaultManipulator(ClassSection(name, "Puma560"), ...) {}
/// @endcode
/// When several levels pass one (a class derived from Puma560 that passes its own), the most
/// derived class's counts. Objects created by name (ObjectManager::createDerivedObject(),
/// ObjectManager::createClassObject()) get their registered class name without it. The
/// temporary must be an argument of the base-class call (it lives until that call returns); the
/// objects the base constructors create in turn are not affected.
class ClassSection {
 public:
  /// Names the class of the object about to be constructed in this thread.
  /// @param[in] name       the object name (empty for an automatic name); must outlive this
  /// @param[in] className  the class name as registered (a string that outlives this)
  /// Real-time safe: no.
  ClassSection(const std::string& name, const char* className) noexcept;
  /// Forgets the class (at the end of the base-class call).
  ~ClassSection();
  ClassSection(const ClassSection&) = delete;             ///< not copyable
  ClassSection& operator=(const ClassSection&) = delete;  ///< not copyable
  /// The object name, for the base class's constructor.
  operator const std::string&() const noexcept { return name_; }

  /// Used by the RoboticObject constructor: the class named for the object under construction
  /// in this thread (the outermost ClassSection made since the last object claimed one), or
  /// nullptr; marks those ClassSections as used, so that objects the constructors create in turn
  /// do not take them.
  /// @return the class name, or nullptr
  static const char* claim() noexcept;

 private:
  const std::string& name_;
  const char* className_;
  bool claimed_ = false;
  ClassSection* outer_;
};

}  // namespace rp
