#pragma once
/// @file
/// The global configuration file `rp.cfg` (paper section 3.5, Figure 9, Table 1) and the
/// control-program files it names with `qmotorConfig`.
///
/// Units in `rp.cfg`: `position x y z` is in millimetres and `orientation r p y` (roll, pitch,
/// yaw about fixed x, y, z) in degrees, so the paper's `position 300 0 0` means 0.3 m. The C++
/// API (`PhysicalObject::setTransform()`) uses metres and radians.

#include <cstddef>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace rp {

/// Error in a configuration file: the message always starts with `FILE:LINE: ` (or `FILE: ` for
/// a file that cannot be read at all).
class ConfigError : public std::runtime_error {
 public:
  /// Creates the error.
  /// @param[in] file     name of the file as the user gave it
  /// @param[in] line     line number counting from 1, or 0 when the error concerns the whole file
  /// @param[in] message  what is wrong, without the location
  ConfigError(const std::string& file, int line, const std::string& message);
  /// The file the error is in.
  const std::string& file() const noexcept { return file_; }
  /// The line the error is on (from 1), or 0 for the whole file.
  int line() const noexcept { return line_; }
  /// The message without the `FILE:LINE: ` prefix.
  const std::string& message() const noexcept { return message_; }
  /// A short excerpt of text from a file for a message: `text` itself when it has at most
  /// kExcerptBytes bytes, else its first bytes (cut at a UTF-8 character boundary) followed by
  /// `...`, so that a huge token is never quoted whole.
  /// @param[in] text  the text to quote
  static std::string excerpt(const std::string& text);
  /// Longest text excerpt() returns unshortened [bytes].
  static constexpr std::size_t kExcerptBytes = 40;

 private:
  std::string file_;
  int line_;
  std::string message_;
};

/// What kind of values a setting takes.
enum class SettingKind {
  Number,  ///< finite decimal numbers
  Integer, ///< whole numbers
  Word,    ///< one word (a device path, a name)
  Choice,  ///< one word out of a fixed list
};

/// Declaration of one setting that a class accepts in its rp.cfg section.
struct SettingSpec {
  std::string name;                  ///< setting name, e.g. `position`
  SettingKind kind = SettingKind::Number;  ///< value kind
  int minValues = 1;                 ///< fewest values after the name
  int maxValues = 1;                 ///< most values after the name
  std::vector<std::string> choices;  ///< allowed words when kind is Choice
  std::string unit;                  ///< unit of the values, e.g. `mm`, `deg` (may be empty)
  std::string description;           ///< one line for help texts and error messages
  /// Smallest value allowed (Number and Integer); Integer settings default to the range of `int`.
  double minValue = std::numeric_limits<double>::lowest();
  /// Largest value allowed (Number and Integer).
  double maxValue = std::numeric_limits<double>::max();
  /// What applies when the setting is absent, as text for the settings reference
  /// (`rp-objects --settings`, docs/settings.md), e.g. `502` or `(none: simulation only)`.
  std::string defaultValue;
};

/// Limits on what a configuration file may hold (a file beyond them is refused with FILE:LINE).
struct ConfigLimits {
  static constexpr std::size_t kMaxFileBytes = 1u << 20;  ///< largest rp.cfg or qmotorConfig file [bytes]
  static constexpr std::size_t kMaxSections = 1000;       ///< most `[name]` sections (objects) in rp.cfg
  static constexpr std::size_t kMaxPlugins = 100;         ///< most `plugin` lines in rp.cfg
  static constexpr std::size_t kMaxPathBytes = 4095;      ///< longest `plugin` or `qmotorConfig` path [bytes]
};

/// The settings a class accepts; each class adds its own to its base class's in a static
/// `declareSettings(SettingSchema&)` (see TypeDatabase).
class SettingSchema {
 public:
  /// Declares a setting of `count` numbers (or between `minCount` and `maxCount`).
  /// @param[in] name         setting name
  /// @param[in] count        number of values
  /// @param[in] unit         unit of the values
  /// @param[in] description  meaning of the values, e.g. `x y z`
  void addNumbers(const std::string& name, int count, const std::string& unit, const std::string& description);
  /// Declares a setting of `count` numbers, each within [minValue, maxValue].
  /// @param[in] name         setting name
  /// @param[in] count        number of values
  /// @param[in] unit         unit of the values
  /// @param[in] description  meaning of the values, e.g. `x y z`
  /// @param[in] minValue     smallest value allowed
  /// @param[in] maxValue     largest value allowed
  void addNumbers(const std::string& name, int count, const std::string& unit, const std::string& description,
                  double minValue, double maxValue);
  /// Declares a setting of one integer within the range of `int`.
  /// @param[in] name         setting name
  /// @param[in] description  meaning of the value
  void addInteger(const std::string& name, const std::string& description);
  /// Declares a setting of one integer within [minValue, maxValue].
  /// @param[in] name         setting name
  /// @param[in] description  meaning of the value
  /// @param[in] minValue     smallest value allowed
  /// @param[in] maxValue     largest value allowed
  void addInteger(const std::string& name, const std::string& description, long long minValue, long long maxValue);
  /// Declares a setting of one word (for example a device path such as `/dev/ser1`).
  /// @param[in] name         setting name
  /// @param[in] description  meaning of the value
  void addWord(const std::string& name, const std::string& description);
  /// Declares a setting of `minCount` to `maxCount` words (names, `joint=value` pairs, ...).
  /// @param[in] name         setting name
  /// @param[in] minCount     fewest words
  /// @param[in] maxCount     most words
  /// @param[in] description  meaning of the words
  /// @param[in] unit         unit of the values the words carry (may be empty)
  void addWords(const std::string& name, int minCount, int maxCount, const std::string& description,
                const std::string& unit = "");
  /// Declares a setting whose one value is a word out of `choices`.
  /// @param[in] name         setting name
  /// @param[in] choices      the allowed words
  /// @param[in] description  meaning of the value
  void addChoice(const std::string& name, const std::vector<std::string>& choices, const std::string& description);
  /// Records what applies when a declared setting is absent (shown by `rp-objects --settings`).
  /// @param[in] name   a setting declared before
  /// @param[in] value  the default as text, e.g. `502`
  /// @throws std::logic_error if `name` is not declared
  void setDefault(const std::string& name, const std::string& value);
  /// Adds a fully described setting (replaces one of the same name).
  /// @param[in] spec  the declaration
  void add(const SettingSpec& spec);
  /// The declaration of a setting, or nullptr if it is not known.
  /// @param[in] name  setting name
  const SettingSpec* find(const std::string& name) const;
  /// All declared settings in declaration order.
  const std::vector<SettingSpec>& settings() const noexcept { return specs_; }
  /// The declared names, comma separated and sorted, for error messages.
  std::string knownNames() const;

 private:
  std::vector<SettingSpec> specs_;
};

/// One `name value...` line of a configuration file.
struct ConfigSetting {
  std::string name;                 ///< first word of the line
  std::vector<std::string> values;  ///< the other words
  int line = 0;                     ///< line number, from 1
};

/// A `name value...` file without sections: the control-program (`qmotorConfig`) file that
/// holds initial values of tunable parameters and log settings (see ControlProgram).
class ParameterFile {
 public:
  /// Reads and checks the syntax of a parameter file.
  /// @param[in] fileName  path of the file
  /// @throws ConfigError  if it cannot be read, is not a regular file, is larger than
  ///         ConfigLimits::kMaxFileBytes, is binary, or a line is malformed
  static ParameterFile read(const std::string& fileName);
  /// Parses text as a parameter file named `fileName` (for messages).
  /// @param[in] text      file contents
  /// @param[in] fileName  name used in error messages
  /// @throws ConfigError  on a malformed line
  static ParameterFile parse(const std::string& text, const std::string& fileName);
  /// The file name given to read() or parse().
  const std::string& fileName() const noexcept { return fileName_; }
  /// The lines in file order.
  const std::vector<ConfigSetting>& entries() const noexcept { return entries_; }
  /// An error located at `entry`'s line.
  /// @param[in] entry    a line of this file
  /// @param[in] message  what is wrong
  ConfigError errorAt(const ConfigSetting& entry, const std::string& message) const;

 private:
  std::string fileName_;
  std::vector<ConfigSetting> entries_;
};

/// One `[name]` section of rp.cfg: the configuration of one object.
class ConfigSection {
 public:
  /// Object name (the text between the brackets).
  const std::string& name() const noexcept { return name_; }
  /// Value of the `class` setting.
  const std::string& className() const noexcept { return className_; }
  /// Line of the `[name]` header.
  int line() const noexcept { return line_; }
  /// Whether this is a class section: named after its class (`[Puma560]` with `class Puma560`),
  /// it configures the objects of that class that have no section of their own.
  bool isClassSection() const noexcept { return name_ == className_; }
  /// Line of the `class` setting.
  int classLine() const noexcept { return classLine_; }
  /// File the section is in.
  const std::string& fileName() const noexcept { return fileName_; }
  /// Every setting except `class`, in file order.
  const std::vector<ConfigSetting>& settings() const noexcept { return settings_; }
  /// The setting called `name`, or nullptr.
  /// @param[in] name  setting name
  const ConfigSetting* find(const std::string& name) const;
  /// Whether the section has a setting called `name`.
  /// @param[in] name  setting name
  bool has(const std::string& name) const { return find(name) != nullptr; }
  /// The values of setting `name` as numbers (already checked against the class's schema).
  /// @param[in] name  setting name
  /// @throws ConfigError if missing or not numeric
  std::vector<double> getNumbers(const std::string& name) const;
  /// The first value of setting `name` as a word.
  /// @param[in] name  setting name
  /// @throws ConfigError if missing
  std::string getWord(const std::string& name) const;
  /// The parsed `qmotorConfig` file, or nullptr if the section has none.
  const ParameterFile* qmotorConfig() const noexcept { return qmotor_.get(); }
  /// An error located at `setting`'s line in this section's file.
  /// @param[in] setting  a setting of this section
  /// @param[in] message  what is wrong
  ConfigError errorAt(const ConfigSetting& setting, const std::string& message) const;

 private:
  friend class Configuration;
  std::string name_, className_, fileName_;
  int line_ = 0, classLine_ = 0;
  std::vector<ConfigSetting> settings_;
  std::shared_ptr<const ParameterFile> qmotor_;
};

/// The parsed global configuration file: its sections and `plugin` lines.
///
/// Syntax (Figure 9): `[name]` starts a section; inside it, each line is `setting value...`;
/// `#` starts a comment (at the start of a line or after white space); blank lines are ignored.
/// Outside sections only `plugin path/to/libfoo.so` is allowed: the library is loaded before the
/// classes are checked, so classes it registers can be named in the file.
///
/// A section named after a registered class (`[Puma560]`) is a class section: its `class` must be
/// that class, and it configures every object of the class that has no section of its own (the
/// paper's unnamed `Puma560 puma;`); see RoboticObject::configSection().
class Configuration {
 public:
  /// How much of the file to check.
  struct Options {
    bool loadPlugins = true;    ///< dlopen the `plugin` libraries (off in the fuzzer)
    bool checkClasses = true;   ///< check classes and settings against the type database
    bool readQMotorFiles = true;  ///< read and check the `qmotorConfig` files
  };

  /// An empty configuration (no objects configured).
  Configuration() = default;
  /// Reads, parses and checks a configuration file (a regular file of at most
  /// ConfigLimits::kMaxFileBytes; a leading UTF-8 byte-order mark is skipped).
  /// @param[in] fileName  path of rp.cfg
  /// @param[in] options   what to check
  /// @throws ConfigError  with FILE:LINE for any problem
  static Configuration read(const std::string& fileName, const Options& options);
  /// Reads a configuration file with every check on.
  /// @param[in] fileName  path of rp.cfg
  /// @throws ConfigError  with FILE:LINE for any problem
  static Configuration read(const std::string& fileName) { return read(fileName, Options{}); }
  /// Parses and checks text as if it were the file `fileName` (relative `qmotorConfig` and
  /// `plugin` paths are taken relative to that file's folder).
  /// @param[in] text      file contents
  /// @param[in] fileName  name used in messages and for relative paths
  /// @param[in] options   what to check
  /// @throws ConfigError  with FILE:LINE for any problem
  static Configuration parse(const std::string& text, const std::string& fileName, const Options& options);
  /// Parses text with every check on.
  /// @param[in] text      file contents
  /// @param[in] fileName  name used in messages
  /// @throws ConfigError  with FILE:LINE for any problem
  static Configuration parse(const std::string& text, const std::string& fileName = "rp.cfg") {
    return parse(text, fileName, Options{});
  }
  /// The file name (empty for an empty configuration).
  const std::string& fileName() const noexcept { return fileName_; }
  /// All sections in file order.
  const std::vector<ConfigSection>& sections() const noexcept { return sections_; }
  /// The section `[name]`, or nullptr.
  /// @param[in] name  object name
  const ConfigSection* findSection(const std::string& name) const;
  /// The class section of class `className` (`[Puma560]` with `class Puma560`), or nullptr.
  /// @param[in] className  a class name
  const ConfigSection* findClassSection(const std::string& className) const;
  /// The section names, comma separated, for error messages.
  std::string sectionNames() const;
  /// The `plugin` lines (paths as resolved against the file's folder).
  const std::vector<ConfigSetting>& plugins() const noexcept { return plugins_; }

 private:
  std::string fileName_;
  std::vector<ConfigSection> sections_;
  std::vector<ConfigSetting> plugins_;
};

}  // namespace rp
