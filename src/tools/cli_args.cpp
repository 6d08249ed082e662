#include "cli_args.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace camera_imu_alignment {

CliArgs::CliArgs(int argc, char** argv, const std::set<std::string>& with_value,
                 const std::set<std::string>& flags) {
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    std::string value;
    bool has_inline_value = false;
    const auto eq = arg.find('=');
    if (arg.rfind("--", 0) == 0 && eq != std::string::npos) {
      value = arg.substr(eq + 1);
      arg = arg.substr(0, eq);
      has_inline_value = true;
    }
    if (flags.count(arg)) {
      if (has_inline_value) throw UsageError("option " + arg + " takes no value");
      values_[arg] = "";
    } else if (with_value.count(arg)) {
      if (!has_inline_value) {
        if (i + 1 >= argc) throw UsageError("option " + arg + " needs a value");
        value = argv[++i];
      }
      if (values_.count(arg)) throw UsageError("option " + arg + " given twice");
      values_[arg] = value;
    } else {
      throw UsageError("unknown argument '" + std::string(argv[i]) + "'");
    }
  }
}

std::string CliArgs::get(const std::string& name, const std::string& fallback) const {
  const auto it = values_.find(name);
  return it == values_.end() ? fallback : it->second;
}

long CliArgs::getInt(const std::string& name, long fallback, long min, long max) const {
  if (!has(name)) return fallback;
  const std::string text = get(name);
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE || v < min || v > max) {
    throw UsageError(name + " must be an integer in [" + std::to_string(min) + ", " +
                     std::to_string(max) + "], got '" + text + "'");
  }
  return v;
}

double CliArgs::getDouble(const std::string& name, double fallback, double min, double max) const {
  if (!has(name)) return fallback;
  const std::string text = get(name);
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v) || v < min || v > max) {
    throw UsageError(name + " must be a number in [" + std::to_string(min) + ", " +
                     std::to_string(max) + "], got '" + text + "'");
  }
  return v;
}

}  // namespace camera_imu_alignment
