// Reader of the BROAD benchmark CSV files (CIA_REALDATA_DIR/broad, optional real data: see
// test/CMakeLists.txt; tests skip when absent) into the core library's sample structs, plus the
// reference orientation and the authors' `moving` label.
//
// Columns (found by header name): t_s, gyr_x/y/z (rad/s), acc_x/y/z (m/s^2), mag_x/y/z_uT
// (microtesla, converted here to tesla), ref_qw/qx/qy/qz (q_ref_imu: IMU-frame vectors into the
// ENU-aligned reference frame; NaN where the motion capture lost the marker), moving (0 rest, 1
// moving).
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "camera_imu_alignment/inertial/inertial_samples.h"

#ifndef CIA_REALDATA_DIR
#error "CIA_REALDATA_DIR (the optional real recordings) is defined by test/CMakeLists.txt"
#endif

namespace camera_imu_alignment {
namespace test {

struct BroadRecording {
  std::vector<ImuSample> imu;
  std::vector<MagneticSample> mag;        ///< tesla, same stamps as imu
  std::vector<Eigen::Quaterniond> ref_q;  ///< q_ref_imu; coefficients NaN when unavailable
  std::vector<int> moving;                ///< 0 at rest, 1 moving (authors' label)
  std::size_t size() const { return imu.size(); }
  bool refValid(std::size_t i) const { return std::isfinite(ref_q[i].w()); }
};

inline std::string broadPath(const std::string& file_name) {
  return std::string(CIA_REALDATA_DIR) + "/broad/" + file_name;
}

/// Reads one BROAD CSV; nullopt when the file is absent or unreadable (tests then skip).
inline std::optional<BroadRecording> loadBroad(const std::string& file_name) {
  std::ifstream in(broadPath(file_name));
  if (!in) return std::nullopt;
  std::string line;
  if (!std::getline(in, line)) return std::nullopt;
  std::map<std::string, int> col;
  {
    std::stringstream ss(line);
    std::string name;
    int k = 0;
    while (std::getline(ss, name, ',')) {
      while (!name.empty() && (name.back() == '\r' || name.back() == ' ')) name.pop_back();
      col[name] = k++;
    }
  }
  const char* names[] = {"t_s",    "gyr_x",  "gyr_y",    "gyr_z",    "acc_x",
                         "acc_y",  "acc_z",  "mag_x_uT", "mag_y_uT", "mag_z_uT",
                         "ref_qw", "ref_qx", "ref_qy",   "ref_qz",   "moving"};
  std::vector<int> idx;
  for (const char* n : names) {
    auto it = col.find(n);
    if (it == col.end()) return std::nullopt;
    idx.push_back(it->second);
  }
  BroadRecording rec;
  std::vector<double> values;
  while (std::getline(in, line)) {
    if (line.empty() || line == "\r") continue;
    values.clear();
    const char* p = line.c_str();
    while (true) {
      char* end = nullptr;
      values.push_back(std::strtod(p, &end));  // parses "nan" as NaN
      if (end == p) values.back() = std::nan("");
      p = end;
      while (*p && *p != ',') ++p;
      if (*p != ',') break;
      ++p;
    }
    if (values.size() < col.size()) return std::nullopt;
    auto v = [&](int k) {
      return values[static_cast<std::size_t>(idx[static_cast<std::size_t>(k)])];
    };
    ImuSample s;
    s.stamp_s = v(0);
    s.gyro_rad_s = Eigen::Vector3d(v(1), v(2), v(3));
    s.accel_m_s2 = Eigen::Vector3d(v(4), v(5), v(6));
    MagneticSample m;
    m.stamp_s = s.stamp_s;
    m.field_t = 1e-6 * Eigen::Vector3d(v(7), v(8), v(9));
    rec.imu.push_back(s);
    rec.mag.push_back(m);
    rec.ref_q.emplace_back(v(10), v(11), v(12), v(13));
    rec.moving.push_back(v(14) > 0.5 ? 1 : 0);
  }
  if (rec.imu.empty()) return std::nullopt;
  return rec;
}

/// Index ranges [begin, end) of the runs where moving == 0 (the authors' rests).
inline std::vector<std::pair<std::size_t, std::size_t>> broadRests(const BroadRecording& rec) {
  std::vector<std::pair<std::size_t, std::size_t>> rests;
  std::size_t i = 0;
  while (i < rec.size()) {
    if (rec.moving[i] != 0) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < rec.size() && rec.moving[j] == 0) ++j;
    rests.emplace_back(i, j);
    i = j;
  }
  return rests;
}

/// Mean of the valid reference quaternions in [begin, end) (sign-aligned to the first valid one),
/// as a rotation matrix R_ref_imu; false when none is valid.
inline bool meanReference(const BroadRecording& rec, std::size_t begin, std::size_t end,
                          Eigen::Matrix3d* R) {
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  Eigen::Vector4d first = Eigen::Vector4d::Zero();
  int n = 0;
  for (std::size_t i = begin; i < end; ++i) {
    if (!rec.refValid(i)) continue;
    Eigen::Vector4d q(rec.ref_q[i].w(), rec.ref_q[i].x(), rec.ref_q[i].y(), rec.ref_q[i].z());
    if (n == 0) first = q;
    if (q.dot(first) < 0) q = -q;
    sum += q;
    ++n;
  }
  if (n == 0) return false;
  sum.normalize();
  *R = Eigen::Quaterniond(sum(0), sum(1), sum(2), sum(3)).toRotationMatrix();
  return true;
}

}  // namespace test
}  // namespace camera_imu_alignment
