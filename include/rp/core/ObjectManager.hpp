#pragma once
/// @file
/// The object manager (paper sections 3.6 and 3.10): the list of live objects, creation of
/// objects by name from rp.cfg, and system shutdown.

#include <functional>
#include <string>
#include <vector>

#include "rp/core/Configuration.hpp"
#include "rp/core/RoboticObject.hpp"
#include "rp/core/TypeDatabase.hpp"

namespace rp {

/// Error creating an object: unknown class, missing section, wrong base class. The message
/// names the rp.cfg file and line when there is one.
class ObjectError : public std::runtime_error {
 public:
  /// Creates the error.
  /// @param[in] message  what went wrong
  explicit ObjectError(const std::string& message) : std::runtime_error(message) {}
};

/// A handle on the process's one object registry: any number of `ObjectManager` values may
/// exist (the paper writes `ObjectManager om;`), and they all see the same objects.
///
/// All methods may be called from any non-real-time thread. Pointers returned stay valid while
/// the object lives; a thread other than the owner should hold no pointer across the object's
/// destruction.
class ObjectManager {
 public:
  /// A handle on the registry. Real-time safe: no.
  ObjectManager() = default;

  /// All live objects in creation order. Real-time safe: no.
  std::vector<RoboticObject*> getObjects() const;
  /// The live objects derived from `T`, in creation order. Real-time safe: no.
  template <typename T>
  std::vector<T*> getDerivedObjects() const {
    std::vector<T*> out;
    for (RoboticObject* o : getObjects())
      if (T* t = dynamic_cast<T*>(o)) out.push_back(t);
    return out;
  }
  /// The object called `name`, or nullptr. Real-time safe: no.
  /// @param[in] name  object name
  RoboticObject* findObject(const std::string& name) const;
  /// The object called `name` if it is derived from `T`, else nullptr.
  /// @param[in] name  object name
  template <typename T>
  T* findObject(const std::string& name) const {
    return dynamic_cast<T*>(findObject(name));
  }
  /// References to every published object (see RoboticObject::publishObject()), in creation
  /// order: while a reference is held, the object's destruction cannot begin, so another thread
  /// (the Scene Viewer) may call its functions. Objects not yet published, or withdrawn, are left
  /// out. Real-time safe: no.
  std::vector<ObjectReference> getPublishedObjects() const;
  /// The same into `out` (emptied first), reusing its capacity: a thread that lists the objects
  /// again and again (the ROS 2 bridge after every servo cycle) allocates only when their number
  /// grows. Real-time safe: no (it takes the registry's lock).
  /// @param[out] out  references to every published object, in creation order
  void getPublishedObjects(std::vector<ObjectReference>& out) const;
  /// A reference to the published object called `name`; empty if there is none (or it is not
  /// published). Real-time safe: no.
  /// @param[in] name  object name
  ObjectReference findPublishedObject(const std::string& name) const;
  /// The names of all live objects in creation order, published or not (a name is safe to read
  /// at any time). Real-time safe: no.
  std::vector<std::string> getObjectNames() const;
  /// Name and class of every live object (plain data for the GUI's object list).
  std::vector<ObjectInfo> getObjectList() const;
  /// Calls `f` for each live object while holding the registry lock (objects cannot be
  /// registered or removed meanwhile; `f` must not create or destroy objects).
  /// @param[in] f  function to call
  void forEachObject(const std::function<void(RoboticObject&)>& f) const;

  /// Creates the object `name` of the class that rp.cfg names in section `[name]`, and returns
  /// it as a `T*`. The manager owns it (deleteObject() destroys it; the rest are destroyed at exit).
  /// @param[in] name  object name = rp.cfg section
  /// @throws ObjectError if the section is missing, the class unknown, or not derived from `T`
  /// @throws ConfigError if the object's settings are invalid
  /// Real-time safe: no.
  template <typename T>
  T* createDerivedObject(const std::string& name) {
    const TypeInfo& info = checkedClass(name, typeName<T>(), [](const TypeInfo& i) {
      try {
        i.throwNullPointer();
      } catch (T*) {
        return true;
      } catch (...) {
      }
      return false;
    });
    return dynamic_cast<T*>(create(info, name));
  }
  /// Creates the object `name` of whatever class rp.cfg names for it.
  /// @param[in] name  object name = rp.cfg section
  /// @throws ObjectError, ConfigError as createDerivedObject()
  RoboticObject* createObject(const std::string& name) { return createDerivedObject<RoboticObject>(name); }
  /// Creates an unnamed object of the registered class `className`, as the program's
  /// `Puma560 puma;` would: configured from the class section `[className]` if rp.cfg has one.
  /// The manager owns it like the objects of createDerivedObject().
  /// @param[in] className  a registered class name
  /// @throws ObjectError if the class is not registered
  /// @throws ConfigError if the object's settings are invalid
  /// Real-time safe: no.
  RoboticObject* createClassObject(const std::string& className);
  /// Creates every object of the global configuration, in file order. Class sections
  /// (`[Puma560]` with `class Puma560`) configure other objects and create none.
  /// @throws ObjectError, ConfigError as createDerivedObject()
  std::vector<RoboticObject*> createAllObjects();
  /// Destroys an object created by this manager.
  /// @param[in] object  object from createDerivedObject()
  /// @throws std::invalid_argument if the manager does not own it
  void deleteObject(RoboticObject* object);
  /// Destroys every object the manager created (newest first).
  void deleteAllObjects();

  /// Asks for a system shutdown with a reason. Only the first request counts. A manager thread
  /// then calls startShutdown() on every object, waits (bounded) for isShutdownComplete(),
  /// stops every ControlProgram, completes the log file and reports the reason on stderr.
  /// @param[in] reason  a string that lives as long as the program (copied to a fixed buffer)
  /// Real-time safe: yes (no allocation, no lock; async-signal-safe).
  static void requestSystemShutdown(const char* reason) noexcept;
  /// Whether a system shutdown has been requested. Real-time safe: yes.
  static bool isShutdownRequested() noexcept;
  /// Waits until a requested system shutdown has finished.
  /// @param[in] timeoutSeconds  longest wait [s]; negative waits forever
  /// @return true if it finished in time
  static bool waitForShutdown(double timeoutSeconds = -1);
  /// The reason given with the first request (empty if none).
  static std::string getShutdownReason();
  /// Shuts every object down now, in the calling thread: startShutdown() on each, then waits
  /// up to the shutdown timeout for isShutdownComplete().
  /// @param[in] reason  why (printed)
  /// @return the names of the objects that did not complete in time (empty on success)
  std::vector<std::string> shutdownAllObjects(const std::string& reason);
  /// Sets the bound on waiting for objects to complete their shutdown (default 5 s).
  /// @param[in] seconds  timeout [s]
  static void setShutdownTimeout(double seconds);
  /// Clears a finished system shutdown so the process can go on (used by tests).
  static void resetShutdown();

  /// The type database.
  static TypeDatabase& getTypeDatabase() { return TypeDatabase::instance(); }

 private:
  template <typename T>
  static std::string typeName() {
    const TypeInfo* i = TypeDatabase::instance().find(std::type_index(typeid(T)));
    return i ? i->name : demangle(typeid(T).name());
  }
  static std::string demangle(const char* mangled);
  const TypeInfo& checkedClass(const std::string& name, const std::string& baseName,
                               const std::function<bool(const TypeInfo&)>& derives) const;
  RoboticObject* create(const TypeInfo& info, const std::string& name);
};

}  // namespace rp
