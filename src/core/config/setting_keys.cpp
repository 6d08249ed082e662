// The non-template parts of the settings tables (setting_keys.h).
#include "camera_imu_alignment/config/setting_keys.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace camera_imu_alignment {

std::string formatSettingNumber(double value) {
  char text[64];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(text, sizeof(text), "%.*g", digits, value);
    if (std::strtod(text, nullptr) == value) break;
  }
  return text;
}

std::string rangeText(const SettingRange& range, bool integer) {
  const bool has_min = std::isfinite(range.min);
  const bool has_max = std::isfinite(range.max);
  const std::string kind = integer ? "an integer" : (has_max ? "a number" : "a finite number");
  const std::string min = formatSettingNumber(range.min);
  const std::string max = formatSettingNumber(range.max);
  if (has_min && has_max) {
    return kind + " within " + (range.min_open ? "(" : "[") + min + ", " + max +
           (range.max_open ? ")" : "]");
  }
  if (has_min) return kind + (range.min_open ? " > " : " >= ") + min;
  if (has_max) return kind + (range.max_open ? " < " : " <= ") + max;
  return kind;
}

std::string wordsText(const std::vector<std::string>& words) {
  std::string text;
  for (std::size_t i = 0; i < words.size(); ++i) {
    if (i > 0) text += i + 1 == words.size() ? " or " : ", ";
    text += "'" + words[i] + "'";
  }
  return text;
}

namespace {

/// Levenshtein distance (insertions, deletions, substitutions).
std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t substitution = diagonal + (a[i - 1] == b[j - 1] ? 0 : 1);
      diagonal = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, substitution});
    }
  }
  return row[b.size()];
}

}  // namespace

std::string closestKey(const std::string& name, const std::vector<std::string>& names) {
  std::string best;
  std::size_t best_distance = 0;
  for (const std::string& candidate : names) {
    const std::size_t distance = editDistance(name, candidate);
    if (best.empty() || distance < best_distance) {
      best = candidate;
      best_distance = distance;
    }
  }
  if (best.empty() || best_distance > 3 || 2 * best_distance >= name.size()) return "";
  return best;
}

std::string unknownKeyMessage(const std::string& name, const std::vector<std::string>& names) {
  std::string message = "unknown key '" + name + "' (see config/default.yaml)";
  const std::string closest = closestKey(name, names);
  if (!closest.empty()) message += "; did you mean '" + closest + "'?";
  return message;
}

}  // namespace camera_imu_alignment
