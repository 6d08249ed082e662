#include "camera_imu_alignment/io/csv_io.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

#include "camera_imu_alignment/io/atomic_file.h"

namespace camera_imu_alignment {
namespace {

std::string trim(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return "";
  const auto last = s.find_last_not_of(" \t\r\n");
  return s.substr(first, last - first + 1);
}

std::vector<std::string> splitComma(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) cells.push_back(trim(cell));
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

/// A CSV table read row by row, columns looked up by header name.
class CsvTable {
 public:
  CsvTable(const std::string& path, const std::vector<std::string>& required) : path_(path) {
    std::ifstream in(path);
    if (!in) throw InputError(path + ": cannot open file");
    std::string line;
    int line_no = 0;
    int header_line = 0;
    bool have_header = false;
    while (std::getline(in, line)) {
      ++line_no;
      const std::string t = trim(line);
      if (t.empty() || t[0] == '#') continue;
      if (!have_header) {
        const auto names = splitComma(t);
        for (size_t i = 0; i < names.size(); ++i) columns_[names[i]] = i;
        std::string missing;
        for (const auto& name : required) {
          if (!columns_.count(name)) missing += (missing.empty() ? "" : ", ") + name;
        }
        if (!missing.empty()) {
          throw InputError(path + ":" + std::to_string(line_no) + ": header lacks column(s) " +
                           missing + " (header: '" + t + "')");
        }
        have_header = true;
        header_line = line_no;
        continue;
      }
      rows_.push_back({line_no, splitComma(t)});
    }
    if (in.bad()) throw InputError(path + ": read error");
    // Name the last line read (a zero-byte file has none).
    const std::string at = line_no > 0 ? ":" + std::to_string(line_no) : "";
    if (!have_header) throw InputError(path + at + ": empty file (no header row)");
    if (rows_.empty()) {
      throw InputError(path + ":" + std::to_string(header_line) +
                       ": no data rows after the header");
    }
  }

  size_t size() const { return rows_.size(); }
  bool hasColumn(const std::string& column) const { return columns_.count(column) > 0; }
  int lineNumber(size_t row) const { return rows_[row].first; }

  double value(size_t row, const std::string& column) const {
    const auto& cells = rows_[row].second;
    const size_t c = columns_.at(column);
    if (c >= cells.size() || cells[c].empty()) fail(row, "missing value for column " + column);
    const char* text = cells[c].c_str();
    char* end = nullptr;
    const double v = std::strtod(text, &end);
    if (end == text || *end != '\0')
      fail(row, "column " + column + ": '" + cells[c] + "' is not a number");
    if (!std::isfinite(v))
      fail(row, "column " + column + ": value '" + cells[c] + "' is not finite");
    return v;
  }

  /// Reads four columns as a quaternion (w, x, y, z), checks its norm and normalises it.
  Eigen::Quaterniond quaternion(size_t row, const std::string& w, const std::string& x,
                                const std::string& y, const std::string& z) const {
    // Read in column order (argument evaluation order is unspecified): the first missing or bad
    // column is the one reported.
    const double qw = value(row, w), qx = value(row, x), qy = value(row, y), qz = value(row, z);
    Eigen::Quaterniond q(qw, qx, qy, qz);
    const double norm = q.norm();
    if (std::abs(norm - 1.0) > kQuaternionNormTolerance) {
      std::ostringstream msg;
      msg << "quaternion (" << w << ", " << x << ", " << y << ", " << z << ") has norm " << norm
          << ", not 1 (tolerance " << kQuaternionNormTolerance << ")";
      fail(row, msg.str());
    }
    return Eigen::Quaterniond(q.coeffs() / norm);
  }

  [[noreturn]] void fail(size_t row, const std::string& what) const {
    throw InputError(path_ + ":" + std::to_string(lineNumber(row)) + ": " + what);
  }

 private:
  std::string path_;
  std::map<std::string, size_t> columns_;
  std::vector<std::pair<int, std::vector<std::string>>> rows_;
};

void writeQuaternion(std::ostream& out, const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  q.normalize();
  out << q.w() << ',' << q.x() << ',' << q.y() << ',' << q.z();
}

}  // namespace

RotationPairs readPairsCsv(const std::string& path) {
  const CsvTable table(path, {"qa_w", "qa_x", "qa_y", "qa_z", "qb_w", "qb_x", "qb_y", "qb_z"});
  RotationPairs pairs(table.size());
  for (size_t i = 0; i < table.size(); ++i) {
    pairs[i].A_cam = table.quaternion(i, "qa_w", "qa_x", "qa_y", "qa_z").toRotationMatrix();
    pairs[i].B_imu = table.quaternion(i, "qb_w", "qb_x", "qb_y", "qb_z").toRotationMatrix();
  }
  return pairs;
}

std::vector<PoseOrientation> readPosesCsv(const std::string& path) {
  const CsvTable table(path, {"stamp", "cam_qw", "cam_qx", "cam_qy", "cam_qz", "imu_qw", "imu_qx",
                              "imu_qy", "imu_qz"});
  std::vector<PoseOrientation> poses(table.size());
  for (size_t i = 0; i < table.size(); ++i) {
    poses[i].stamp_s = table.value(i, "stamp");
    poses[i].R_target_cam =
        table.quaternion(i, "cam_qw", "cam_qx", "cam_qy", "cam_qz").toRotationMatrix();
    poses[i].R_world_imu =
        table.quaternion(i, "imu_qw", "imu_qx", "imu_qy", "imu_qz").toRotationMatrix();
    if (table.hasColumn("group")) {
      const double group = table.value(i, "group");
      if (group != std::floor(group) || std::abs(group) > 1e9) {
        table.fail(i, "column group: '" + std::to_string(group) + "' is not an integer");
      }
      poses[i].group = static_cast<int>(group);
    }
  }
  return poses;
}

void writePairsCsv(const std::string& path, const RotationPairs& pairs) {
  std::ostringstream out;
  out.precision(17);
  out << "qa_w,qa_x,qa_y,qa_z,qb_w,qb_x,qb_y,qb_z\n";
  for (const auto& p : pairs) {
    writeQuaternion(out, p.A_cam);
    out << ',';
    writeQuaternion(out, p.B_imu);
    out << '\n';
  }
  writeFileAtomically(path, out.str());
}

void writePosesCsv(const std::string& path, const std::vector<PoseOrientation>& poses) {
  std::ostringstream out;
  out.precision(17);
  // The group column only when there is more than one group (poses of different groups are never
  // paired); files of a single group keep the plain header.
  const bool groups = std::any_of(poses.begin(), poses.end(), [&](const PoseOrientation& p) {
    return p.group != poses.front().group;
  });
  out << "stamp,cam_qw,cam_qx,cam_qy,cam_qz,imu_qw,imu_qx,imu_qy,imu_qz" << (groups ? ",group" : "")
      << "\n";
  for (const auto& p : poses) {
    out << p.stamp_s << ',';
    writeQuaternion(out, p.R_target_cam);
    out << ',';
    writeQuaternion(out, p.R_world_imu);
    if (groups) out << ',' << p.group;
    out << '\n';
  }
  writeFileAtomically(path, out.str());
}

}  // namespace camera_imu_alignment
