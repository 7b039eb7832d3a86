#pragma once
/// @file
/// The base class of every robotic object (paper section 3.2, Figure 5).

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "rp/core/ClassSection.hpp"
#include "rp/core/Configuration.hpp"

namespace rp {

class ControlProgram;
class ObjectManager;
class ObjectReference;

/// What a GUI field shows or edits.
enum class FieldKind {
  Number,   ///< one number
  Vector,   ///< `size` numbers
  Boolean,  ///< on/off
  Text,     ///< a string
  Choice,   ///< one of `choices`
};

/// One field of an object's control panel: plain data a GUI can render.
struct ControlPanelField {
  std::string name;                  ///< identifier, e.g. `kp`; for tunable fields the parameter name
  std::string label;                 ///< text shown to the user
  FieldKind kind = FieldKind::Number;  ///< what the field holds
  int size = 1;                      ///< number of values (Vector)
  std::string unit;                  ///< unit, e.g. `rad`, `N m`
  double min = 0;                    ///< lower limit of the range (Number, Vector)
  double max = 0;                    ///< upper limit of the range; min == max means unbounded
  bool tunable = false;              ///< true: editable (a ControlProgram parameter); false: read-only
  int stateIndex = -1;               ///< index of the first value in StateSnapshot::values, or -1
  std::vector<std::string> choices;  ///< the words of a Choice field
};

/// An object's control panel (paper Figure 18): a title and fields.
struct ControlPanel {
  std::string title;                     ///< panel title
  std::vector<ControlPanelField> fields;  ///< fields in display order
};

/// Capacity of StateSnapshot::values.
inline constexpr int kMaxStateValues = 128;

/// A fixed-size copy of an object's state, published by its servo thread without blocking and
/// read by the GUI (see TripleBuffer). Trivially copyable.
struct StateSnapshot {
  double time = 0;           ///< clock time of the cycle that published it [s]
  /// Clock time its inputs (the arm's joints) hold for [s]: from hardware, when the cycle read them
  /// (from a board that samples on its own: when it sampled them; a sample read again keeps its
  /// time); of a simulation (integrated to `time`) or on a simulated clock, `time`; 0 if not said.
  double readTime = 0;
  std::uint64_t cycle = 0;   ///< cycle number
  int size = 0;              ///< number of valid entries in `values`
  double values[kMaxStateValues] = {};  ///< values laid out as the control panel's stateIndex says
};

/// Error status of an object: 0 means no error.
struct ErrorStatus {
  int code = 0;         ///< 0: no error; otherwise an object-specific code
  std::string message;  ///< what went wrong
};

/// An interactive command of an object (e.g. "Open Gripper"), listed by the GUI in its pop-up menu.
struct CommandInfo {
  std::string name;         ///< command name, used to invoke it
  std::string description;  ///< one line for a tooltip
};

/// Name and class of a live object: an entry of the object list.
struct ObjectInfo {
  std::string name;       ///< object name
  std::string className;  ///< class name as registered in the type database
  bool physical = false;  ///< derived from PhysicalObject
  bool hasControlLoop = false;  ///< runs a ControlProgram
};

/// Base class of every robotic object: error status, interactive commands, configuration from
/// rp.cfg, shutdown, control panel, message handler and thread management (Figure 5).
///
/// An object registers with the ObjectManager in its constructor and leaves it in its
/// destructor, from any thread. An object created with a name is configured from the rp.cfg
/// section of that name (each constructor level reads its own settings from configSection());
/// an object created without a name gets a unique automatic name such as `object_3` and is
/// configured from the section named after its class, `[Puma560]`, if rp.cfg has one (see
/// ClassSection); so is a named object whose name has no section.
///
/// Threads: an object is in the ObjectManager's list from the start of its construction to the
/// end of its destruction. Its name is safe to read from any thread at any time. Other threads
/// (the Scene Viewer) use anything else only while the object is *published*: from the end of its
/// construction (publishObject(), called last by the most-derived constructor, by
/// startControlLoop() and by the ObjectManager's factory) to the start of its destruction
/// (withdrawObject(), called first by the most-derived destructor, by stopControlLoop() and by
/// ObjectManager::deleteObject()), and only through an ObjectReference, which withdrawObject()
/// waits for. The servo threads never take part in this: they neither wait for it nor delay it.
///
/// Classes that can be named in rp.cfg have a constructor taking `const std::string& name`
/// and are registered with RP_REGISTER_CLASS (see TypeDatabase.hpp). The settings a class
/// accepts are declared in a static `declareSettings(SettingSchema&)` that first calls its
/// base class's.
class RoboticObject {
 public:
  /// Creates the object and registers it with the ObjectManager.
  /// @param[in] name  object name; empty for an automatic name. If the global configuration has
  ///                  a section of this name, the object is configured from it.
  /// @throws std::invalid_argument if another live object has the same name
  /// Real-time safe: no.
  explicit RoboticObject(const std::string& name = "");
  /// Leaves the ObjectManager.
  virtual ~RoboticObject();
  RoboticObject(const RoboticObject&) = delete;             ///< objects are not copyable
  RoboticObject& operator=(const RoboticObject&) = delete;  ///< objects are not copyable

  /// Declares the settings every object accepts (`class` and `qmotorConfig` are handled by the
  /// parser and always allowed).
  /// @param[out] schema  schema to add to
  static void declareSettings(SettingSchema& schema);

  /// Object name (the given one, or the automatic `object_N`). Safe from any thread.
  /// Real-time safe: no.
  std::string getName() const;
  /// Whether the name was generated automatically.
  bool hasAutomaticName() const noexcept;
  /// Class name as registered in the type database (or the C++ name without namespaces).
  /// Real-time safe: no.
  virtual std::string getClassName() const;
  /// The rp.cfg section that configures this object, or nullptr if there is none: the section
  /// named after the object (`[leader]`) if there is one, otherwise the section named after its
  /// class (`[Puma560]`, for unnamed objects and named ones without a section of their own; the
  /// class is the one its constructor names with ClassSection, or the registered class for
  /// objects created by name). The two are never merged: a named section replaces the class's.
  const ConfigSection* configSection() const noexcept;
  /// The class whose section an object without a section of its own is configured from (see
  /// ClassSection), or an empty string if its constructor named none.
  std::string getConfiguredClass() const;

  /// @name Error handling
  /// @{

  /// Sets the error status; a code of 0 clears it. The message is truncated to 255 bytes.
  /// @param[in] code     error code, 0 for none
  /// @param[in] message  what went wrong (NUL-terminated)
  /// Real-time safe: yes (copies into a fixed buffer; never blocks on another thread for more
  /// than a bounded number of attempts).
  void setError(int code, const char* message) noexcept;
  /// Clears the error status. Real-time safe: yes.
  void clearError() noexcept { setError(0, ""); }
  /// The error code, 0 for none. Real-time safe: yes.
  int getErrorCode() const noexcept;
  /// The error status with its message. Real-time safe: no.
  ErrorStatus getErrorStatus() const;
  /// @}

  /// @name Interactive commands
  /// @{

  /// Registers a command invocable by name from a program or the GUI.
  /// @param[in] name         command name, e.g. `Open Gripper`
  /// @param[in] action       what it does (runs in the caller's thread)
  /// @param[in] description  one line for the GUI
  /// @throws std::invalid_argument if a command of that name exists
  /// Real-time safe: no.
  void addCommand(const std::string& name, std::function<void()> action, const std::string& description = "");
  /// Registers a command whose action says what it did, e.g. "arm power on" (the GUI shows it); a
  /// command that cannot be carried out throws, and the GUI shows why.
  /// @param[in] name         command name
  /// @param[in] action       what it does (runs in the caller's thread); returns the result text
  /// @param[in] description  one line for the GUI
  /// @throws std::invalid_argument if a command of that name exists
  /// Real-time safe: no.
  void addCommandWithResult(const std::string& name, std::function<std::string()> action,
                            const std::string& description = "");
  /// Withdraws the command `name` (a command offered only while something exists, such as a
  /// manipulator's "Servo Control: NAME"). A run of it already started goes on.
  /// @param[in] name  command name
  /// @return whether there was such a command
  /// Real-time safe: no.
  bool removeCommand(const std::string& name);
  /// The registered commands in registration order. Real-time safe: no.
  std::vector<CommandInfo> getCommands() const;
  /// Runs the command `name`.
  /// @param[in] name  command name
  /// @return what the command did (its action's text; "done" for a command added with addCommand())
  /// @throws std::invalid_argument if there is no such command (the message lists the known ones);
  ///         whatever the action throws when it cannot be carried out
  /// Real-time safe: no.
  std::string executeCommand(const std::string& name);
  /// @}

  /// @name Shutdown
  /// @{

  /// Starts shutting the object down (bring it to rest, switch off power); must not block long.
  /// The default marks the shutdown complete at once. Real-time safe: no.
  virtual void startShutdown();
  /// Whether the shutdown started by startShutdown() is complete. Real-time safe: yes.
  virtual bool isShutdownComplete() const;
  /// Whether startShutdown() has been called. Real-time safe: yes.
  bool isShuttingDown() const noexcept;
  /// Asks the ObjectManager to shut the whole system down (see ObjectManager::requestSystemShutdown).
  /// @param[in] reason  a string that lives as long as the program (e.g. a literal)
  /// Real-time safe: yes.
  void requestSystemShutdown(const char* reason) noexcept;
  /// @}

  /// @name GUI
  /// @{

  /// The control panel description; the default has the object's name and class as title, its
  /// error code, and one tunable field per parameter of its control program (if any).
  /// Real-time safe: no.
  virtual ControlPanel getControlPanel() const;
  /// Copies the latest state published by the object; false if it publishes none (default).
  /// @param[out] snapshot  receives the state
  /// Real-time safe: no (may wait for other readers).
  virtual bool getStateSnapshot(StateSnapshot& snapshot) const;
  /// Handles a custom message; the default understands none.
  /// @param[in]  type     message type
  /// @param[in]  payload  message body (text, for example JSON)
  /// @param[out] reply    the answer
  /// @return true if the message was understood
  /// Real-time safe: no.
  virtual bool handleMessage(const std::string& type, const std::string& payload, std::string& reply);
  /// @}

  /// @name Thread management
  /// @{

  /// The control program that runs this object's control loop, or nullptr (default). Classes
  /// derived from ControlProgram return `this`.
  virtual ControlProgram* getControlProgram() { return nullptr; }
  /// Whether the object needs a control loop.
  bool needsControlLoop() { return getControlProgram() != nullptr; }
  /// Starts the object's threads: its control loop (if getControlProgram() returns one) and the
  /// additional threads it asked for (addThread(), addPeriodicThread()), then publishes the
  /// object (publishObject()). The most-derived constructor calls it last, so no thread ever sees
  /// a half-constructed object (C++ runs no code of a base class after the most-derived
  /// constructor: the library's classes call it, and ObjectManager's factory calls it for every
  /// object it creates, so a class created by name needs no call). Calling it again does nothing.
  /// Real-time safe: no.
  void startControlLoop();
  /// Lets the object bring what its loop drives to a safe state (beforeControlLoopStops()),
  /// withdraws the object from other threads (withdrawObject()), then stops the control loop and
  /// the additional threads and waits for them (derived destructors call this first; the
  /// RoboticObject destructor stops and joins any thread still running). Calling it again does
  /// nothing more.
  /// Real-time safe: no.
  void stopControlLoop();
  /// Asks for an additional thread (paper section 3.2, "Thread Management"): `body` runs in a
  /// thread of its own from startControlLoop() (at once if that has run already) and must return
  /// soon after `stop` becomes true, which stopControlLoop() and the destructor set before they
  /// wait for it. An exception escaping `body` sets the object's error status (code 1).
  /// @param[in] name  thread name (shown by `top -H`; the first 15 bytes)
  /// @param[in] body  what the thread does
  /// Real-time safe: no.
  void addThread(const std::string& name, std::function<void(const std::atomic<bool>& stop)> body);
  /// Asks for an additional periodic thread: `cycle` is called every `periodSeconds` (absolute
  /// deadlines on the monotonic clock; a late cycle is not repeated) from startControlLoop() until
  /// stopControlLoop(), in the same way as addThread(). The loop itself does not allocate.
  /// @param[in] name           thread name
  /// @param[in] periodSeconds  period [s], more than 0 and at most 3600
  /// @param[in] cycle          what each cycle does
  /// @throws std::invalid_argument for a period out of range
  /// Real-time safe: no.
  void addPeriodicThread(const std::string& name, double periodSeconds, std::function<void()> cycle);
  /// The names of the additional threads asked for, in order. Real-time safe: no.
  std::vector<std::string> getThreadNames() const;
  /// Whether the additional threads have been started and not yet stopped. Real-time safe: yes.
  bool areThreadsRunning() const noexcept;
  /// QMotor's Stop (paper section 3.8): stops the object's control program, which can be started
  /// again (startControlProgram()). The default stops the loop after its current cycle; a class
  /// whose loop drives hardware brings it to a safe state first (a manipulator: a damped hold until
  /// the arm is at rest, then the power off and the brakes on, where it came to rest).
  /// @return what was done, for the page
  /// @throws std::invalid_argument if the object runs no control program
  /// @throws std::logic_error if the program is not running
  /// Real-time safe: no.
  virtual std::string stopControlProgram();
  /// QMotor's Start: starts the object's control program again after stopControlProgram(). A
  /// manipulator's loop starts holding the arm where it is (bumpless), powered as before the stop.
  /// @return what was done
  /// @throws std::invalid_argument if the object runs no control program
  /// @throws std::logic_error saying why not: it runs already, the system or the object is
  ///         shutting down, or the object has an error
  /// Real-time safe: no.
  virtual std::string startControlProgram();
  /// QMotor's Restart: stopControlProgram() if the program runs, then startControlProgram().
  /// @return what was done
  /// @throws as those two
  /// Real-time safe: no.
  std::string restartControlProgram();
  /// The control-program file (`qmotorConfig`) of the object's rp.cfg section, or "" if it has none.
  /// Real-time safe: no.
  std::string getQMotorConfigFile() const;
  /// The folder QMotor saves and loads the object's control-program files in: the folder of its
  /// `qmotorConfig` file, else the folder of the rp.cfg that configures it, else "" (none).
  /// Real-time safe: no.
  std::string getQMotorConfigFolder() const;
  /// Called first by stopControlLoop() while the loop still runs: a class whose loop drives
  /// hardware waits here until it is safe to stop (a manipulator holds its arm until at rest and
  /// switches the power off). The default does nothing.
  virtual void beforeControlLoopStops() {}
  /// @}

  /// A plain description of the object for the object list. Real-time safe: no.
  ObjectInfo getInfo();

  /// @name Publication to other threads
  /// @{

  /// Publishes the object: from now on other threads may use it through an ObjectReference
  /// (ObjectManager::getPublishedObjects()). Call it last in the most-derived constructor, after
  /// which nothing of the object is written without its own synchronisation; startControlLoop()
  /// and ObjectManager's factory call it. A program may call it for an object of a class that
  /// does not (for example a plain PhysicalObject) once the object is constructed.
  ///
  /// Called by the thread that constructed the object, it also publishes the objects that thread
  /// constructed after this one and has not published (they are complete: the objects this
  /// object's constructor made, such as its members, or objects made after it); they are
  /// withdrawn with this object, so they must not be destroyed before it by another thread.
  /// Real-time safe: no (takes the object registry's lock).
  void publishObject() noexcept;
  /// Withdraws the object (and the objects published with it) from other threads: no new
  /// ObjectReference to them can be taken, and the call waits until every reference other
  /// threads hold has been released. Call it first in the
  /// most-derived destructor; stopControlLoop(), ObjectManager::deleteObject() and the
  /// destructors of RoboticObject and PhysicalObject call it (later than ideal for derived classes).
  /// References held by the calling thread itself are not waited for.
  /// Real-time safe: no (waits for other threads' references).
  void withdrawObject() noexcept;
  /// Whether the object is published (constructed and not withdrawn). Real-time safe: yes.
  bool isObjectPublished() const noexcept;
  /// @}

 protected:
  /// Applies the `qmotorConfig` file of the object's rp.cfg section to its control program, once
  /// (later calls do nothing); startControlLoop() calls it before the loop starts, so it works for
  /// every class that runs a control program (a class may call it earlier in its constructor).
  /// @throws ConfigError naming FILE:LINE for a bad line of the file (an unknown name, a wrong
  ///         count, a value out of range), or the rp.cfg line of `qmotorConfig` if the object runs
  ///         no control program (the file would be ignored)
  /// Real-time safe: no.
  void applyQMotorConfigFile();
  /// Marks the shutdown complete (for classes overriding startShutdown()). Real-time safe: yes.
  void setShutdownComplete() noexcept;
  /// For the actions of a device's commands (addCommandWithResult()): returns `done` when the
  /// device carried the command out (`ok`), else throws std::runtime_error with the object's error
  /// status (what its driver said), so the GUI shows why the command failed.
  /// @param[in] ok    whether the device carried the command out
  /// @param[in] done  the result text
  /// Real-time safe: no.
  std::string commandResult(bool ok, const std::string& done) const;

 private:
  friend class ObjectManager;
  friend class ObjectReference;
  bool tryReference() noexcept;  // takes a reference if published
  bool isWithdrawn() const noexcept;  // withdrawn: being destroyed
  void startThreads();  // the additional threads asked for and not yet running
  void stopThreads() noexcept;  // sets their stop flag and joins them
  void releaseReference() noexcept;

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A counted reference to a published object (see RoboticObject::publishObject()): while it is
/// held, the object's withdrawObject() waits, so its destruction cannot begin. Move-only; obtained
/// from ObjectManager::getPublishedObjects() or ObjectManager::findPublishedObject(). Hold it only
/// as long as the object is used, never while waiting for the object's owner thread, and release
/// it in the thread that took it.
class ObjectReference {
 public:
  /// An empty reference.
  ObjectReference() noexcept = default;
  /// Releases the reference.
  ~ObjectReference() { reset(); }
  /// Takes over another reference.
  /// @param[in,out] other  reference left empty
  ObjectReference(ObjectReference&& other) noexcept : object_(other.object_) { other.object_ = nullptr; }
  /// Releases this reference and takes over another.
  /// @param[in,out] other  reference left empty
  /// @return this reference
  ObjectReference& operator=(ObjectReference&& other) noexcept {
    if (this != &other) {
      reset();
      object_ = other.object_;
      other.object_ = nullptr;
    }
    return *this;
  }
  ObjectReference(const ObjectReference&) = delete;             ///< not copyable
  ObjectReference& operator=(const ObjectReference&) = delete;  ///< not copyable

  /// The object, or nullptr for an empty reference. Real-time safe: yes.
  RoboticObject* get() const noexcept { return object_; }
  /// The object (the reference must not be empty).
  RoboticObject* operator->() const noexcept { return object_; }
  /// The object (the reference must not be empty).
  RoboticObject& operator*() const noexcept { return *object_; }
  /// Whether the reference holds an object.
  explicit operator bool() const noexcept { return object_ != nullptr; }
  /// The object as a `T*` if it is derived from `T`, else nullptr.
  template <typename T>
  T* as() const {
    return dynamic_cast<T*>(object_);
  }
  /// Releases the reference (it becomes empty). Real-time safe: yes.
  void reset() noexcept {
    if (object_) object_->releaseReference();
    object_ = nullptr;
  }

 private:
  friend class ObjectManager;
  explicit ObjectReference(RoboticObject* referenced) noexcept : object_(referenced) {}
  RoboticObject* object_ = nullptr;
};

}  // namespace rp
