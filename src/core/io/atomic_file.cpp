#include "camera_imu_alignment/io/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "camera_imu_alignment/common/input_error.h"

namespace camera_imu_alignment {
namespace {

std::string reason(int error) { return std::string(" (") + std::strerror(error) + ")"; }

/// The folder `path` is written in ("." for a bare file name).
std::filesystem::path folderOf(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  return parent.empty() ? std::filesystem::path(".") : parent;
}

/// Writes all of `data` to `fd`; false with errno set on failure.
bool writeAll(int fd, const std::string& data) {
  std::size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace

void writeFileAtomically(const std::string& path, const std::string& contents) {
  const std::string tmp = path + ".tmp";
  const std::string unchanged = "; the previous file is unchanged";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) {
    throw InputError(path + ": cannot write the temporary file " + tmp + reason(errno) + unchanged);
  }
  // A file on a device (a link to /dev/full, say) cannot be synced: only a failed write counts.
  const bool written = writeAll(fd, contents) && (::fsync(fd) == 0 || errno == EINVAL);
  const int write_errno = errno;
  const bool closed = ::close(fd) == 0;
  if (!written || !closed) {
    std::remove(tmp.c_str());
    throw InputError(path + ": write error" + reason(written ? errno : write_errno) + unchanged);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int rename_errno = errno;
    std::remove(tmp.c_str());
    throw InputError(path + ": cannot replace the file" + reason(rename_errno) + unchanged);
  }
}

std::string whyNotWritable(const std::string& path) {
  if (path.empty()) return "no file name given";
  const std::filesystem::path folder = folderOf(path);
  std::error_code ec;
  if (!std::filesystem::exists(folder, ec)) {
    return path + ": the folder " + folder.string() + " does not exist";
  }
  if (!std::filesystem::is_directory(folder, ec)) {
    return path + ": " + folder.string() + " is not a folder";
  }
  if (std::filesystem::is_directory(path, ec)) return path + ": is a folder, not a file";
  // A probe file, as the atomic write's temporary one would be: permissions, a read-only file
  // system and root's privileges are all what the write will meet.
  const std::string probe = path + ".tmp";
  const bool probe_existed = std::filesystem::exists(std::filesystem::symlink_status(probe, ec));
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0666);
  if (fd < 0) {
    return path + ": cannot create a file in " + folder.string() + reason(errno);
  }
  ::close(fd);
  if (!probe_existed) std::remove(probe.c_str());
  return "";
}

}  // namespace camera_imu_alignment
