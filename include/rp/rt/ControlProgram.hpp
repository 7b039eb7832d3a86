#pragma once
/// @file
/// ControlProgram: a periodic real-time loop with statistics, log variables and tunable
/// parameters (paper section 3.8: QMotor's role).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rp/math/Matrix.hpp"

namespace rp {

class Clock;
class LogWriter;
class ParameterFile;

/// Summary of a set of durations, in microseconds.
struct LatencyStatistics {
  std::uint64_t count = 0;  ///< number of samples
  double min = 0;           ///< smallest [µs]
  double mean = 0;          ///< mean [µs]
  double p50 = 0;           ///< median [µs] (1 µs histogram bins up to 10 ms)
  double p99 = 0;           ///< 99th percentile [µs] (same bins)
  double max = 0;           ///< largest [µs]
};

/// Statistics of a control program since start().
struct ControlStatistics {
  std::uint64_t cycles = 0;      ///< cycles run
  std::uint64_t overruns = 0;    ///< cycles that ended after the next deadline
  std::uint64_t missedCycles = 0;  ///< deadlines skipped because of overruns (cycles that never ran)
  LatencyStatistics wakeupLatency;    ///< how late the thread woke after each deadline (real clock)
  LatencyStatistics computationTime;  ///< time of its read, control and write phases in each cycle
  std::uint64_t logSamples = 0;       ///< log samples taken
  std::uint64_t lostLogSamples = 0;   ///< log samples dropped because the ring buffer was full
  bool realTimeScheduling = false;    ///< the thread runs with SCHED_FIFO
  bool simulatedClock = false;        ///< the program runs on a simulated clock
  bool ownThread = false;             ///< the program has a thread of its own (ThreadMode::Own)
  std::size_t executorPrograms = 0;   ///< programs its executor stepped (itself included) when it joined it
};

/// How a control program's loop is run (docs/realtime.md, Executors).
enum class ThreadMode {
  Shared,  ///< stepped with every program of the same clock, rate, priority and CPU by one thread (the default)
  Own      ///< in a thread of its own (rp.cfg `thread own`)
};

/// Statistics of one executor: the thread that steps the programs of one clock, rate, priority
/// and CPU (ControlProgram::getExecutorStatistics()).
struct ExecutorStatistics {
  double rate = 0;                   ///< loop rate [Hz]
  int priority = 0;                  ///< SCHED_FIFO priority
  int cpu = -1;                      ///< CPU it is pinned to, or -1
  std::vector<int> cpus;             ///< the CPUs of its threads when spread (setExecutorCpus()), else empty
  bool ownThread = false;            ///< a program's thread of its own (ThreadMode::Own)
  bool simulatedClock = false;       ///< runs on a simulated clock
  bool realTimeScheduling = false;   ///< the thread runs with SCHED_FIFO
  std::vector<std::string> programs;  ///< the programs it steps, in their order within each phase
  std::uint64_t cycles = 0;          ///< cycles run
  std::uint64_t overruns = 0;        ///< cycles that ended after the next deadline
  std::uint64_t missedCycles = 0;    ///< deadlines skipped because of overruns
  LatencyStatistics wakeupLatency;   ///< how late the thread woke after each deadline (real clock)
  LatencyStatistics cycleTime;       ///< time from the wake-up to the end of the cycle's last phase
  std::string lastOverrunProgram;    ///< the program that took the most time in the last overrun ("" if none)
  double lastOverrunProgramTime = 0;  ///< its computation time in that cycle [µs]
};

/// A registered log variable (name and size fixed at configure time).
struct LogVariableInfo {
  std::string name;  ///< name, e.g. `q`; CSV columns are `program.name` or `program.name[i]`
  std::size_t size = 1;  ///< number of values
  bool vector = false;   ///< registered as a vector (columns get `[i]`)
  std::string unit;      ///< unit, e.g. `rad`
};

/// A registered tunable parameter.
struct ParameterInfo {
  std::string name;         ///< name, e.g. `kp`
  std::size_t size = 1;     ///< number of values
  double min = 0;           ///< smallest allowed value
  double max = 0;           ///< largest allowed value
  std::string unit;         ///< unit
  std::string description;  ///< one line for the tuning window
};

/// What QMotor's log records (ControlProgram::setLogCapture()): the chosen log variables, every
/// `every`-th cycle, into a buffer of `samples` rows that fills once and stops, from the first
/// cycle or from a trigger: the cycle in which `triggerColumn` crosses `triggerLevel`.
struct LogCaptureSettings {
  std::vector<std::string> variables;  ///< registered log variables (every value of each); empty: all
  unsigned every = 1;                  ///< decimation: one row every `every` cycles, 1..kMaxLogEvery
  std::size_t samples = 10000;         ///< rows kept; samples × (columns + 1) <= kMaxLogCaptureValues
  std::string triggerColumn;           ///< `q[0]` (a vector's value) or `gain` (a scalar); empty: no trigger
  double triggerLevel = 0;             ///< the level the trigger column crosses (finite)
  bool triggerRising = true;           ///< true: from below to at or above the level; false: from above to at or below
};

/// The state of QMotor's log (ControlProgram::getLogCaptureStatus()).
struct LogCaptureStatus {
  bool armed = false;        ///< a capture is set (setLogCapture() since the last clearLogCapture())
  bool triggered = false;    ///< recording: the trigger fired (at once without a trigger)
  double triggerTime = 0;    ///< the program's clock time of the first row [s] (when triggered)
  std::size_t rows = 0;      ///< rows recorded
  std::size_t capacity = 0;  ///< rows it holds; full when rows == capacity
  unsigned every = 1;        ///< decimation
  std::vector<std::string> columns;  ///< CSV columns after `t`: `program.variable` or `program.vector[i]`
  std::string triggerColumn;         ///< as set ("" for none)
  double triggerLevel = 0;           ///< as set
  bool triggerRising = true;         ///< as set
};

/// A periodic control loop (QMotor's ControlProgram), stepped by an executor thread.
///
/// Derive from it and implement control(); register log variables and parameters in the
/// constructor (before start()). start() hands the program to an executor: one periodic thread
/// that steps every program of the same clock, rate, priority and CPU (ThreadMode::Shared, the
/// default), or a thread of the program's own (setThreadMode(ThreadMode::Own), rp.cfg
/// `thread own`). The thread runs at the set rate on its clock: on the real clock with absolute
/// deadlines (`clock_nanosleep`, TIMER_ABSTIME), with `mlockall` and SCHED_FIFO at the set
/// priority when the process may (otherwise one warning and normal scheduling); on a
/// SimulatedClock in lockstep with the other executors on it.
///
/// Each cycle of an executor: wait for the deadline; then in three phases, each over every
/// program in the order they were started: apply parameter changes and readInputs(); control();
/// writeOutputs(); then sample each program's log variables every getLogEvery()-th cycle into a
/// preallocated ring buffer read by a LogWriter's non-real-time thread. So the control() of
/// every program of an executor sees the inputs every other program read in the same cycle
/// (for a manipulator: its joints; DefaultManipulator::getJointPosition() from the executor's
/// thread returns them without a lock). Nothing in the cycle allocates, locks or does I/O
/// (tests/realtime/rt_alloc_test.cpp proves it).
///
/// A derived class whose control() uses its own members must call stop() in its destructor.
class ControlProgram {
 public:
  /// Creates a stopped program.
  /// @param[in] programName  name used for log columns (`name.variable`) and messages
  explicit ControlProgram(const std::string& programName = "control");
  /// Stops the thread if it still runs.
  virtual ~ControlProgram();
  ControlProgram(const ControlProgram&) = delete;             ///< not copyable
  ControlProgram& operator=(const ControlProgram&) = delete;  ///< not copyable

  /// Sets the name used for log columns.
  /// @param[in] name  program name (no `,` or `.`)
  void setProgramName(const std::string& name);
  /// The program name.
  const std::string& getProgramName() const;

  /// @name Timing (set before start())
  /// @{

  /// Highest loop rate setRate() accepts [Hz].
  static constexpr double kMaxRate = 20000;
  /// Largest log ring buffer setLogBufferSize() accepts [samples].
  static constexpr std::size_t kMaxLogBufferSize = 1000000;

  /// Sets the loop rate (default 1000 Hz).
  /// @param[in] hz  rate [Hz], in [1, kMaxRate] (a period of at most 1 s)
  /// @throws std::invalid_argument if out of range or not finite
  /// @throws std::logic_error if running
  void setRate(double hz);
  /// The loop rate [Hz].
  double getRate() const;
  /// The loop period [s].
  double getPeriod() const;
  /// Sets the SCHED_FIFO priority (default 27, as in the paper).
  /// @param[in] priority  1..99
  void setPriority(int priority);
  /// The SCHED_FIFO priority.
  int getPriority() const;
  /// Pins the loop thread to one CPU on the real clock (like cyclictest's `-a CPU`); -1 (the
  /// default) leaves it where the scheduler puts it. A CPU the process may not use is reported
  /// once on stderr and the loop runs unpinned.
  /// @param[in] cpu  a CPU number (0 .. the number of CPUs - 1), or -1
  /// @throws std::invalid_argument if below -1
  /// @throws std::logic_error if running
  void setCpuAffinity(int cpu);
  /// The CPU the loop thread is pinned to, or -1.
  int getCpuAffinity() const;
  /// Runs the program on `clock` (default: RoboticPlatform::getDefaultClock()).
  /// @param[in] clock  a clock that outlives the program's run
  void setClock(Clock& clock);
  /// The clock the program runs on.
  Clock& getClock() const;
  /// Stops the loop by itself after `cycles` cycles (0: never, the default).
  /// @param[in] cycles  number of cycles
  void setCycleLimit(std::uint64_t cycles);
  /// Chooses between the shared executor of the program's clock, rate, priority and CPU
  /// (ThreadMode::Shared) and a thread of its own (ThreadMode::Own). Default:
  /// getDefaultThreadMode() at construction.
  /// @param[in] mode  the thread mode
  /// @throws std::logic_error if running
  void setThreadMode(ThreadMode mode);
  /// The thread mode.
  ThreadMode getThreadMode() const;
  /// Sets the thread mode of programs constructed from now on (default ThreadMode::Shared, or
  /// ThreadMode::Own when the environment variable `RP_CONTROL_THREADS` is `own`).
  /// @param[in] mode  the thread mode
  static void setDefaultThreadMode(ThreadMode mode);
  /// The thread mode of programs constructed from now on.
  static ThreadMode getDefaultThreadMode();
  /// Spreads the shared executors started from now on over several CPUs, for more programs of one
  /// rate than one core can step: an executor on the real clock whose programs have no CPU of
  /// their own (setCpuAffinity()) runs a thread pinned to each CPU of the list, the first one its
  /// loop; the programs are dealt to the threads in turn in the order they joined (program i to
  /// thread i mod the number of CPUs), and the threads meet after each phase, so the phases and
  /// the same-cycle guarantee hold across them. An empty list (the default, unless the environment
  /// variable `RP_EXECUTOR_CPUS` lists CPUs, e.g. `0,1`) keeps one thread per executor. Executors
  /// already running keep their threads; simulated clocks always step an executor in one thread.
  /// @param[in] cpus  two or more distinct CPU numbers, or none
  /// @throws std::invalid_argument for one CPU, a CPU out of range or a CPU listed twice
  static void setExecutorCpus(const std::vector<int>& cpus);
  /// The CPUs shared executors started from now on spread over (empty: one thread each).
  static std::vector<int> getExecutorCpus();
  /// @}

  /// @name Running
  /// @{

  /// Starts the loop thread (calls enterControl() in it, then control() every cycle).
  /// @throws std::logic_error if already running
  /// Real-time safe: no.
  void start();
  /// Asks the loop to end after the current cycle and waits for the thread (from the loop's own
  /// thread it only asks). Real-time safe: no.
  void stop();
  /// Asks the loop to end after the current cycle without waiting. Real-time safe: yes.
  void requestStop() noexcept;
  /// Waits until the loop has ended (cycle limit, requestStop() or stop()).
  /// Real-time safe: no.
  void waitUntilStopped();
  /// Whether the loop thread runs.
  bool isRunning() const noexcept;
  /// Whether the calling thread runs a control loop (any program's). Real-time safe: yes.
  static bool isLoopThread() noexcept;
  /// Time of the current cycle on the program's clock [s]. Real-time safe: yes.
  double getTime() const noexcept;
  /// Number of cycles completed. Real-time safe: yes.
  std::uint64_t getCycleCount() const noexcept;
  /// Number of deadlines skipped since start() because a cycle overran (on the real clock: the
  /// cycles that never ran; the next cycle's time jumps over them). Real-time safe: yes.
  std::uint64_t getMissedCycleCount() const noexcept;
  /// Statistics since start(). Real-time safe: no.
  ControlStatistics getStatistics() const;
  /// Statistics of every executor running now, in the order they were created. Real-time safe: no.
  static std::vector<ExecutorStatistics> getExecutorStatistics();
  /// @}

  /// @name Log variables (register before start())
  /// @{

  /// Registers a scalar log variable sampled from `variable`.
  /// @param[in] name      variable name
  /// @param[in] variable  storage read every sampled cycle (must outlive the program's run)
  /// @param[in] unit      unit
  /// @throws std::invalid_argument for a duplicate or bad name; std::logic_error if running
  void registerLogVariable(const std::string& name, const double& variable, const std::string& unit = "");
  /// Registers a vector log variable of `size` doubles at `data`.
  /// @param[in] name  variable name
  /// @param[in] data  first value (must outlive the program's run)
  /// @param[in] size  number of values
  /// @param[in] unit  unit
  void registerLogVariable(const std::string& name, const double* data, std::size_t size, const std::string& unit = "");
  /// Registers a fixed-size vector (e.g. `Vector<6>` joint positions).
  /// @param[in] name  variable name
  /// @param[in] v     the vector (must outlive the program's run)
  /// @param[in] unit  unit
  template <int n>
  void registerLogVariable(const std::string& name, const Vector<n>& v, const std::string& unit = "") {
    registerLogVariable(name, v.data(), static_cast<std::size_t>(n), unit);
  }
  /// The registered log variables.
  std::vector<LogVariableInfo> getLogVariables() const;
  /// Samples every n-th cycle (default 1).
  /// @param[in] n  decimation, >= 1
  void setLogEvery(unsigned n);
  /// The log decimation.
  unsigned getLogEvery() const;
  /// Sets the ring-buffer capacity in samples (default 4096).
  /// @param[in] samples  capacity, 2 .. kMaxLogBufferSize
  /// @throws std::invalid_argument if out of range; std::logic_error if running
  void setLogBufferSize(std::size_t samples);
  /// Largest decimation setLogEvery() (file log) and setLogCapture() accept [cycles].
  static constexpr unsigned kMaxLogEvery = 1000000;
  /// Largest QMotor log setLogCapture() accepts: rows × (columns + 1) values.
  static constexpr std::size_t kMaxLogCaptureValues = 1000000;
  /// Sets up QMotor's log (paper section 3.8: logging modes), from any thread, running or not:
  /// the chosen variables every `every`-th cycle into a preallocated buffer, from the first
  /// cycle or from the cycle in which the trigger column crosses its level (rising: the previous
  /// value below the level and this one at or above it; falling: the reverse), until the buffer
  /// is full. Replaces the previous capture and its rows. The loop takes the samples after
  /// control() without allocating or locking; this call allocates the buffer and waits for the
  /// loop to let go of the previous one (at most one cycle).
  /// @param[in] settings  what to record
  /// @throws std::invalid_argument naming the field for an unknown variable or trigger column, a
  ///         decimation outside 1..kMaxLogEvery, no rows, too many values, or a level that is not finite
  /// Real-time safe: no.
  void setLogCapture(const LogCaptureSettings& settings);
  /// Removes QMotor's log (and its rows). Real-time safe: no.
  void clearLogCapture();
  /// The state of QMotor's log. Real-time safe: no.
  LogCaptureStatus getLogCaptureStatus() const;
  /// The rows of QMotor's log as CSV in the log file's format (LogWriter): a header
  /// `t,program.variable,program.vector[0],...`, then one row per sample, values as the shortest
  /// text that reads back to the same double.
  /// @throws std::logic_error if no capture is set
  /// Real-time safe: no.
  std::string getLogCaptureCsv() const;
  /// Sends this program's samples to `writer` (default: the platform's `-log` writer, if any).
  /// @param[in] writer  log writer that outlives the run, or nullptr for none
  void setLogWriter(LogWriter* writer);
  /// @}

  /// @name Tunable parameters (register before start(); set from any thread)
  /// @{

  /// Registers a scalar parameter stored in `target`, applied at the start of a cycle.
  /// @param[in] name         parameter name
  /// @param[in,out] target   storage the loop reads (written only by the loop's thread while running)
  /// @param[in] min          smallest allowed value
  /// @param[in] max          largest allowed value
  /// @param[in] unit         unit
  /// @param[in] description  one line for the tuning window
  /// @throws std::invalid_argument for a duplicate name, min > max, or a current value out of range
  void registerParameter(const std::string& name, double& target, double min, double max, const std::string& unit = "",
                         const std::string& description = "");
  /// Registers a vector parameter of `size` values at `target`.
  /// @param[in] name         parameter name
  /// @param[in,out] target   first value
  /// @param[in] size         number of values
  /// @param[in] min          smallest allowed value (each element)
  /// @param[in] max          largest allowed value (each element)
  /// @param[in] unit         unit
  /// @param[in] description  one line for the tuning window
  void registerParameter(const std::string& name, double* target, std::size_t size, double min, double max,
                         const std::string& unit = "", const std::string& description = "");
  /// Registers a fixed-size vector parameter (e.g. `Vector<6>` gains).
  /// @param[in] name         parameter name
  /// @param[in,out] target   the vector
  /// @param[in] min          smallest allowed value
  /// @param[in] max          largest allowed value
  /// @param[in] unit         unit
  /// @param[in] description  one line for the tuning window
  template <int n>
  void registerParameter(const std::string& name, Vector<n>& target, double min, double max,
                         const std::string& unit = "", const std::string& description = "") {
    registerParameter(name, target.data(), static_cast<std::size_t>(n), min, max, unit, description);
  }
  /// Requests a new value for every element of parameter `name`; the loop applies it at the
  /// start of its next cycle (at once when not running).
  /// @param[in] name   parameter name
  /// @param[in] value  new value
  /// @throws std::out_of_range if outside [min, max]; std::invalid_argument for an unknown name
  /// Real-time safe: no.
  void setParameter(const std::string& name, double value);
  /// Requests a new value for element `index` of parameter `name`.
  /// @param[in] name   parameter name
  /// @param[in] index  element, from 0
  /// @param[in] value  new value
  /// @throws std::out_of_range if outside [min, max] or index too large
  void setParameter(const std::string& name, std::size_t index, double value);
  /// Requests new values for all elements of parameter `name` (applied together).
  /// @param[in] name    parameter name
  /// @param[in] values  one value per element
  /// @throws std::out_of_range / std::invalid_argument as above, or for a wrong count
  void setParameter(const std::string& name, const std::vector<double>& values);
  /// The latest requested (or applied) values of parameter `name`.
  /// @param[in] name  parameter name
  std::vector<double> getParameter(const std::string& name) const;
  /// The registered parameters.
  std::vector<ParameterInfo> getParameters() const;
  /// @}

  /// @name Control-program file (`qmotorConfig`)
  /// @{

  /// Applies a control-program file: `name v1 v2 ...` sets parameter `name`; `rate HZ`,
  /// `priority P`, `logEvery N`, `logBufferSize N` and `log var1 var2 ...` (variables to log;
  /// default all) set the program's settings. The whole file is checked before anything is
  /// applied: a bad file changes nothing. While the program runs the settings cannot change (a
  /// file that gives their current values, as saveQMotorConfig() writes them, is accepted) and
  /// the parameters take effect at the start of the next cycle.
  /// @param[in] file  parsed file
  /// @throws ConfigError naming the file and line for an unknown name, a wrong count, a value out
  ///         of range, or a setting that would change while running
  void applyQMotorConfig(const ParameterFile& file);
  /// Writes the current parameters and log settings in the same format.
  /// @param[in] fileName  path to write
  /// @throws std::runtime_error if it cannot be written
  void saveQMotorConfig(const std::string& fileName) const;
  /// @}

  /// Stops every running control program (system shutdown, exit). Real-time safe: no.
  static void stopAll();

 protected:
  /// Called in the loop thread before the program's first cycle (not time-critical, but with a
  /// shared executor it delays that cycle of every program of the executor).
  virtual void enterControl() {}
  /// The read phase of a cycle: read the program's inputs (sensors, encoders). Runs before the
  /// control() of every program of the executor. Default: nothing. Real-time safe: must be.
  virtual void readInputs() {}
  /// One control cycle (the compute phase), after the readInputs() of every program of the
  /// executor and before their writeOutputs(). Must not allocate, lock or do I/O. Real-time
  /// safe: must be.
  virtual void control() = 0;
  /// The write phase of a cycle: write the program's outputs (actuators), after the control()
  /// of every program of the executor. Default: nothing. Real-time safe: must be.
  virtual void writeOutputs() {}
  /// Called in the loop thread after the last cycle.
  virtual void exitControl() {}

 private:
  struct Impl;
  struct Executor;
  friend struct Impl;
  friend struct Executor;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rp
