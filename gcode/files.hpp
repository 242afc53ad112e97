#pragma once
// Reading G-code files and writing program files whole or not at all.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace hybridctl::gcode {

/// The whole file. Throws InputError "PATH: cannot read: <reason>" (also for a directory
/// or a file over `max_bytes`).
std::string read_text_file(const std::filesystem::path& path, std::size_t max_bytes = std::size_t(1) << 30);

/// Writes `text` to `path` atomically (common/atomic_file.hpp): a temporary file beside it,
/// renamed over it only when everything was written. Throws InputError on failure, and
/// then `path` is untouched.
void write_text_file(const std::filesystem::path& path, std::string_view text);

/// Writes several files so that either all appear or none does: every text goes to its
/// temporary file first, and only when all were written are they renamed into place.
/// (A failure during the renames themselves can leave the earlier ones in place.)
void write_text_files(const std::vector<std::pair<std::filesystem::path, std::string>>& files);

}  // namespace hybridctl::gcode
