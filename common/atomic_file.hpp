#pragma once
// Output files appear whole or not at all: writers fill a temporary file beside the
// target and rename it over the target only when everything was written.

#include <filesystem>
#include <string>
#include <system_error>
#include <unistd.h>

#include "common/error.hpp"

namespace hybridctl {

class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target)
      : target_(std::move(target)),
        temp_(target_.parent_path() /
              ("." + target_.filename().string() + ".tmp-" + std::to_string(::getpid()))) {
    const auto dir = target_.parent_path().empty() ? std::filesystem::path(".") : target_.parent_path();
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec)) {
      throw InputError(target_.string() + ": cannot write: directory " + dir.string() +
                       " does not exist");
    }
  }
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile() {
    if (!committed_) {
      std::error_code ec;
      std::filesystem::remove(temp_, ec);
    }
  }

  // Where the writer writes.
  const std::filesystem::path& temp_path() const { return temp_; }
  const std::filesystem::path& target() const { return target_; }

  // Moves the finished temporary file over the target.
  void commit() {
    std::error_code ec;
    std::filesystem::rename(temp_, target_, ec);
    if (ec) throw InputError(target_.string() + ": cannot write: " + ec.message());
    committed_ = true;
  }

 private:
  std::filesystem::path target_;
  std::filesystem::path temp_;
  bool committed_ = false;
};

}  // namespace hybridctl
