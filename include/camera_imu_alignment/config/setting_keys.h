// One way to declare a settings struct's keys: a table of SettingKey, one entry per key, each
// stating once its name, the member it sets, its range (min/max, or the allowed words), its unit
// and a description. Everything else is generated from the entry:
//   * `allowed`, the text of every message about the key ("a finite number > 0", "an integer
//     within [2, 200]", "'optimal' or 'two_step'");
//   * reading a YAML value into the member (a value of the wrong type or an unknown word is refused
//     with `allowed`);
//   * the range check (checkRanges: the first key out of its range, in table order);
//   * the value as text (the defaults check compares config/default.yaml with the struct's
//     defaults through it).
// The pipeline's table (pipeline_config.cpp), the calibrator's (online_config.cpp), the ROS
// wrapper's (wrapper_settings.cpp) and simulate_bag's options (src/tools/simulate_bag_options.cpp)
// are written with it. Every bad value is reported in one form, badValueMessage: "<source>: <key>
// = <value given>: must be <allowed>"; checks across keys are in settings_checks.h.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

/// A table entry's access to the member `path` of the settings (const or not): the `access` of
/// numberKey and the other key makers, e.g. CIA_MEMBER(joint.priors.gyro_scale).
#define CIA_MEMBER(path) \
  [](auto& settings) -> auto& { return settings.path; }

namespace camera_imu_alignment {

/// A numeric range: [min, max], either end open or infinite. Doubles must also be finite.
struct SettingRange {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = false;
  bool max_open = false;

  template <typename T>
  bool contains(T value) const {
    const double v = static_cast<double>(value);
    if (std::is_floating_point<T>::value && !std::isfinite(v)) return false;
    return (min_open ? v > min : v >= min) && (max_open ? v < max : v <= max);
  }
};

/// > min (a positive quantity when min = 0).
inline SettingRange above(double min) { return {min, SettingRange().max, true, false}; }
/// >= min.
inline SettingRange atLeast(double min) { return {min, SettingRange().max, false, false}; }
/// [min, max].
inline SettingRange within(double min, double max) { return {min, max, false, false}; }
/// (min, max).
inline SettingRange between(double min, double max) { return {min, max, true, true}; }

/// A number as short as it can be written and read back unchanged ("0.1", "1.5e-05", "30").
std::string formatSettingNumber(double value);
/// "a finite number > 0", "a number within (0, 1)", "an integer >= 2", "an integer within [2,
/// 200]": what `range` allows for a value of type integer or not.
std::string rangeText(const SettingRange& range, bool integer);
/// "'a' or 'b'", "'a', 'b' or 'c'".
std::string wordsText(const std::vector<std::string>& words);
/// The key of `names` closest to `name` by edit distance, when it is close enough to be a typo
/// (at most 3 edits and fewer than half the name's characters); "" otherwise.
std::string closestKey(const std::string& name, const std::vector<std::string>& names);
/// "unknown key '<name>' (see config/default.yaml)", with "; did you mean '<key>'?" when one of
/// `names` is close (closestKey).
std::string unknownKeyMessage(const std::string& name, const std::vector<std::string>& names);

/// A setting that is not usable: its key and the message ("<key> = <value>: must be ...").
struct SettingProblem {
  std::string key;
  std::string message;
};

template <typename Settings>
struct SettingKey {
  std::string name;         ///< the key in config files and ROS parameters
  std::string unit;         ///< "s", "deg", "rad/s", "m/s^2", "T", "px", "" (a pure number)
  std::string description;  ///< one line, for people (usage texts)
  std::string allowed;      ///< what the key accepts, for messages (generated)
  /// Reads `node` into the settings; throws YAML::Exception on a wrong type or an unknown word.
  std::function<void(const YAML::Node&, Settings*)> read;
  /// The message's range for a value of the right type that is out of range ("" when the key
  /// has no range beyond its type).
  std::string range_allowed;
  /// True when the member's value is within the key's range.
  std::function<bool(const Settings&)> in_range;
  /// The member's value as YAML text (numbers: formatSettingNumber; lists in flow style).
  std::function<std::string(const Settings&)> text;
  /// Numbers: their range, and whether they are whole numbers (for tests and usage texts).
  std::optional<SettingRange> range = std::nullopt;
  bool integer = false;
};

/// A number (int, std::size_t or double) within `range`; `access(settings)` is a reference to the
/// member (const and non-const).
template <typename T, typename Settings, typename Access>
SettingKey<Settings> numberKey(const std::string& name, Access access, SettingRange range,
                               const std::string& unit, const std::string& description) {
  const bool integer = std::is_integral<T>::value;
  std::string allowed = rangeText(range, integer);
  // A whole number of the right type is told the interval alone ("within [2, 200]"); numbers and
  // one-sided ranges keep the full text.
  std::string range_allowed = allowed;
  const std::string integer_within = "an integer within ";
  if (integer && range_allowed.compare(0, integer_within.size(), integer_within) == 0) {
    range_allowed = range_allowed.substr(std::string("an integer ").size());
  }
  return {
      name,
      unit,
      description,
      allowed,
      [access](const YAML::Node& node, Settings* s) { access(*s) = node.as<T>(); },
      range_allowed,
      [access, range](const Settings& s) { return range.contains(access(s)); },
      [access](const Settings& s) { return formatSettingNumber(static_cast<double>(access(s))); },
      range,
      integer};
}

/// true or false.
template <typename Settings, typename Access>
SettingKey<Settings> boolKey(const std::string& name, Access access,
                             const std::string& description) {
  return {name,
          "",
          description,
          "true or false",
          [access](const YAML::Node& node, Settings* s) { access(*s) = node.as<bool>(); },
          "",
          [](const Settings&) { return true; },
          [access](const Settings& s) { return std::string(access(s) ? "true" : "false"); },
          std::nullopt,
          false};
}

/// Free text (a path, a frame name); `allowed` says what it is.
template <typename Settings, typename Access>
SettingKey<Settings> textKey(const std::string& name, Access access, const std::string& allowed,
                             const std::string& description) {
  return {name,
          "",
          description,
          allowed,
          [access](const YAML::Node& node, Settings* s) { access(*s) = node.as<std::string>(); },
          "",
          [](const Settings&) { return true; },
          [access](const Settings& s) { return access(s); },
          std::nullopt,
          false};
}

/// One of `words`; the member is an enum read with `parse(word, &value)` (false: unknown) and
/// written with `to_string(value)`, or a std::string (parse and to_string null).
template <typename Settings, typename Access, typename Parse, typename ToString>
SettingKey<Settings> wordKey(const std::string& name, Access access,
                             const std::vector<std::string>& words, Parse parse, ToString to_string,
                             const std::string& description) {
  return {name,
          "",
          description,
          wordsText(words),
          [access, parse](const YAML::Node& node, Settings* s) {
            if (!parse(node.as<std::string>(), &access(*s))) {
              throw YAML::Exception(node.Mark(), "unknown word");
            }
          },
          "",
          [](const Settings&) { return true; },
          [access, to_string](const Settings& s) { return std::string(to_string(access(s))); },
          std::nullopt,
          false};
}

/// A text member that must be one of `words`.
template <typename Settings, typename Access>
SettingKey<Settings> wordKey(const std::string& name, Access access,
                             const std::vector<std::string>& words,
                             const std::string& description) {
  auto parse = [words](const std::string& text, std::string* value) {
    for (const std::string& word : words) {
      if (word == text) {
        *value = text;
        return true;
      }
    }
    return false;
  };
  auto to_string = [](const std::string& value) { return value; };
  return wordKey<Settings>(name, access, words, parse, to_string, description);
}

/// A value as the user wrote it: a scalar's text, a list or map in YAML flow style.
inline std::string yamlText(const YAML::Node& node) {
  if (node.IsScalar()) return node.Scalar();
  if (node.IsNull()) return "(empty)";
  YAML::Emitter out;
  out << YAML::Flow << node;
  return out.c_str();
}

/// The one form of every bad-value message: "<source>: <key> = <value>: must be <allowed>".
inline std::string badValueMessage(const std::string& source, const std::string& key,
                                   const std::string& value, const std::string& allowed) {
  return source + ": " + key + " = " + value + ": must be " + allowed;
}

/// The key named `name` in `table`, or nullptr.
template <typename Settings>
const SettingKey<Settings>* findKey(const std::vector<SettingKey<Settings>>& table,
                                    const std::string& name) {
  for (const auto& key : table) {
    if (key.name == name) return &key;
  }
  return nullptr;
}

/// The names of a table, in its order.
template <typename Settings>
std::vector<std::string> keyNames(const std::vector<SettingKey<Settings>>& table) {
  std::vector<std::string> names;
  for (const auto& key : table) names.push_back(key.name);
  return names;
}

/// The first key of `table` whose value is out of its range: "<key> = <value>: must be <range>".
template <typename Settings>
std::optional<SettingProblem> checkRanges(const std::vector<SettingKey<Settings>>& table,
                                          const Settings& settings) {
  for (const auto& key : table) {
    if (key.in_range(settings)) continue;
    return SettingProblem{key.name,
                          key.name + " = " + key.text(settings) + ": must be " + key.range_allowed};
  }
  return std::nullopt;
}

/// Reads `value` into `settings` with `key`; a wrong type or unknown word is refused with
/// badValueMessage (as a SettingsError naming `source` and the key).
template <typename Settings>
void readKey(const SettingKey<Settings>& key, const std::string& source, const YAML::Node& value,
             Settings* settings);

}  // namespace camera_imu_alignment

#include "camera_imu_alignment/config/settings_error.h"

namespace camera_imu_alignment {

template <typename Settings>
void readKey(const SettingKey<Settings>& key, const std::string& source, const YAML::Node& value,
             Settings* settings) {
  try {
    key.read(value, settings);
  } catch (const YAML::Exception&) {
    throw SettingsError(source, key.name,
                        key.name + " = " + yamlText(value) + ": must be " + key.allowed);
  }
}

}  // namespace camera_imu_alignment
