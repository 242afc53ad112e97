#include "drivers/journal.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <thread>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/error.hpp"

namespace hybridctl::drivers {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kFileName = "journal.jsonl";
// Space kept aside for the last entries when the disk fills up: released on ENOSPC so the
// entry that failed, and the note that the host stopped, still get written.
constexpr const char* kReserveName = "journal.reserve";
constexpr std::size_t kReserveBytes = 64 * 1024;

// A test hook (docs/drivers.md "Soak run"): HYBRIDCTL_JOURNAL_FULL_AT=BYTES makes every
// write that would take the journal past BYTES fail with ENOSPC, until the reserve is
// released (the space it frees lifts the limit by its size).
std::uint64_t injected_full_at() {
  const char* v = std::getenv("HYBRIDCTL_JOURNAL_FULL_AT");
  return v && *v ? std::strtoull(v, nullptr, 10) : 0;
}

void make_reserve(const fs::path& directory) {
  const fs::path path = directory / kReserveName;
  if (fs::exists(path)) return;
  std::ofstream out(path, std::ios::binary);
  const std::string block(4096, '\0');
  for (std::size_t n = 0; n < kReserveBytes && out; n += block.size()) out.write(block.data(), std::streamsize(block.size()));
}

double seconds_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string hex64(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

}  // namespace

// fdatasync on a thread of its own, on a duplicate of the journal's descriptor (the same
// open file: it syncs what the journal wrote). A request while one is running makes one
// more after it, so every line written before a request is on disk when a sync ends.
struct Journal::BackgroundSync {
  explicit BackgroundSync(int journal_fd) : fd(::fcntl(journal_fd, F_DUPFD_CLOEXEC, 0)) {
    thread = std::thread([this] { run(); });
  }
  ~BackgroundSync() {
    {
      std::lock_guard lock(mutex);
      stop = true;
    }
    wake.notify_one();
    thread.join();
    if (fd >= 0) ::close(fd);
  }
  void request() {
    {
      std::lock_guard lock(mutex);
      pending = true;
    }
    wake.notify_one();
  }
  void run() {
    std::unique_lock lock(mutex);
    while (true) {
      wake.wait(lock, [&] { return pending || stop; });
      if (!pending) return;
      pending = false;
      lock.unlock();
      if (fd >= 0) ::fdatasync(fd);
      lock.lock();
    }
  }

  int fd;
  std::mutex mutex;
  std::condition_variable wake;
  bool pending = false, stop = false;
  std::thread thread;
};

Journal::Journal(fs::path path, int fd, JournalHeader header, JournalProgress progress)
    : path_(std::move(path)), fd_(fd), last_sync_(seconds_now()), header_(std::move(header)), progress_(progress) {}

Journal::Journal(Journal&& o) noexcept
    : sync_period_s(o.sync_period_s), path_(std::move(o.path_)), fd_(o.fd_), last_sync_(o.last_sync_),
      header_(std::move(o.header_)), progress_(o.progress_), background_(std::move(o.background_)),
      write_failed_(o.write_failed_), bytes_written_(o.bytes_written_) {
  o.fd_ = -1;
}

Journal& Journal::operator=(Journal&& o) noexcept {
  if (this != &o) {
    close();
    sync_period_s = o.sync_period_s;
    path_ = std::move(o.path_);
    fd_ = o.fd_;
    last_sync_ = o.last_sync_;
    header_ = std::move(o.header_);
    progress_ = o.progress_;
    background_ = std::move(o.background_);
    write_failed_ = o.write_failed_;
    bytes_written_ = o.bytes_written_;
    o.fd_ = -1;
  }
  return *this;
}

Journal::~Journal() { close(); }

void Journal::close() {
  background_.reset();  // waits for a sync in progress
  if (fd_ >= 0) {
    ::fsync(fd_);
    ::close(fd_);
    fd_ = -1;
  }
}

Journal Journal::create(const fs::path& directory, const JournalHeader& header) {
  std::error_code ec;
  fs::create_directories(directory, ec);
  if (!fs::is_directory(directory)) throw InputError(directory.string() + ": cannot make the job directory");
  const fs::path path = directory / kFileName;
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0)
    throw InputError(path.string() + ": cannot start a journal: " + std::strerror(errno) +
                     (errno == EEXIST ? " (a job directory holds one job: resume it with --resume, or choose another)" : ""));
  make_reserve(directory);
  Journal j(path, fd, header, {});
  const json h = {{"journal", "hybridctl-job"}, {"version", 1},          {"program", header.program},
                  {"identity", hex64(header.identity)},                  {"lines", header.lines},
                  {"machine", header.machine}, {"transport", header.transport}, {"source", header.source}};
  j.append(h.dump(), true);
  // The directory entry too, so the file survives a crash right after creation.
  const int dfd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
  return j;
}

Journal Journal::open(const fs::path& directory) {
  const fs::path path = directory / kFileName;
  std::ifstream in(path);
  if (!in) throw InputError(path.string() + ": no journal here (expected the --job directory of an earlier run)");
  JournalHeader header;
  JournalProgress progress;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const std::string where = path.string() + ":" + std::to_string(number) + ": ";
    json j;
    try {
      j = json::parse(line);
    } catch (const json::parse_error&) {
      // The last line may be torn by a crash mid-write: anything before it is whole.
      if (in.peek() == EOF) break;
      throw InputError(where + "not a JSON object; expected a journal line written by hybridctl run");
    }
    try {
      if (number == 1) {
        if (j.value("journal", "") != "hybridctl-job" || j.value("version", 0) != 1)
          throw InputError(where + "expected a hybridctl job journal, version 1");
        header.program = j.at("program").get<std::string>();
        header.identity = std::stoull(j.at("identity").get<std::string>(), nullptr, 16);
        header.lines = j.at("lines").get<std::uint32_t>();
        header.machine = j.at("machine").get<std::string>();
        header.transport = j.at("transport").get<std::string>();
        header.source = j.value("source", "");
      } else if (j.contains("chunk")) {
        progress.last_chunk = j.at("chunk").get<std::uint32_t>();
        progress.through_line = j.at("through_line").get<std::uint32_t>();
        progress.executed_line = j.at("executed_line").get<std::uint32_t>();
        progress.held_by_host = false;
      } else if (j.contains("lost")) {
        progress.lost = true;
        progress.lost_executed_line = j.at("executed_line").get<std::uint32_t>();
        progress.lost_accepted_line = j.at("accepted_line").get<std::uint32_t>();
      } else if (j.contains("restart")) {
        const json& r = j.at("restart");
        header.program = r.at("program").get<std::string>();
        header.identity = std::stoull(r.at("identity").get<std::string>(), nullptr, 16);
        header.lines = r.at("lines").get<std::uint32_t>();
        header.restart_from_line = r.at("from_line").get<std::uint32_t>();
        header.restart_preamble_lines = r.at("preamble_lines").get<std::uint32_t>();
        header.original_program = r.at("original_program").get<std::string>();
        progress = {};
      } else if (j.contains("held_by_host")) {
        progress.held_by_host = true;
      } else if (j.contains("completed")) {
        progress.completed = true;
        progress.executed_line = j.at("completed").get<std::uint32_t>();
      }
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      throw InputError(where + "malformed journal entry: " + e.what());
    }
  }
  if (number == 0) throw InputError(path.string() + ": empty journal; expected a header line");
  const int fd = ::open(path.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  if (fd < 0) throw InputError(path.string() + ": cannot append: " + std::strerror(errno));
  make_reserve(directory);
  Journal j(path, fd, header, progress);
  j.bytes_written_ = fs::file_size(path);
  return j;
}

void Journal::append(const std::string& line, bool sync) {
  const std::string text = line + "\n";
  std::size_t done = 0;
  static const std::uint64_t full_at = injected_full_at();
  while (done < text.size()) {
    const bool injected = full_at && !write_failed_ && bytes_written_ + (text.size() - done) > full_at;
    const ssize_t n = injected ? (errno = ENOSPC, -1) : ::write(fd_, text.data() + done, text.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      if ((errno == ENOSPC || errno == EDQUOT) && !write_failed_) {
        // The disk is full: free the reserve and write this entry (a chunk the controller
        // took must not go unrecorded); from now on the journal is not writable and the
        // streamer stops sending.
        write_failed_ = true;
        std::error_code ec;
        fs::remove(path_.parent_path() / kReserveName, ec);
        continue;
      }
      throw std::runtime_error(path_.string() + ": cannot write the journal: " + std::strerror(errno));
    }
    done += std::size_t(n);
    bytes_written_ += std::uint64_t(n);
  }
  if (sync) {
    ::fsync(fd_);
    last_sync_ = seconds_now();
  }
}

void Journal::acknowledged(std::uint32_t chunk, std::uint32_t through_line, std::uint32_t executed_line) {
  progress_.last_chunk = chunk;
  progress_.through_line = through_line;
  progress_.executed_line = executed_line;
  const json j = {{"chunk", chunk}, {"through_line", through_line}, {"executed_line", executed_line}};
  append(j.dump(), false);
  const double now = seconds_now();
  if (now - last_sync_ >= sync_period_s) {
    if (!background_) background_ = std::make_unique<BackgroundSync>(fd_);
    background_->request();
    last_sync_ = now;
  }
}

void Journal::lost(const std::string& kind, const std::string& what, std::uint32_t executed_line,
                   std::uint32_t accepted_line) {
  progress_.lost = true;
  progress_.lost_executed_line = executed_line;
  progress_.lost_accepted_line = accepted_line;
  append(json{{"lost", kind}, {"what", what}, {"executed_line", executed_line}, {"accepted_line", accepted_line}}.dump(), true);
}

void Journal::restarted(const std::string& program, std::uint64_t identity, std::uint32_t lines, std::uint32_t from_line,
                        std::uint32_t preamble_lines, const std::string& original_program) {
  header_.original_program = original_program;
  header_.program = program;
  header_.identity = identity;
  header_.lines = lines;
  header_.restart_from_line = from_line;
  header_.restart_preamble_lines = preamble_lines;
  progress_ = {};
  append(json{{"restart", {{"program", program}, {"identity", hex64(identity)}, {"lines", lines}, {"from_line", from_line},
                           {"preamble_lines", preamble_lines},
                           {"original_program", original_program}}}}
             .dump(),
         true);
}

void Journal::held_by_host(const std::string& why) {
  progress_.held_by_host = true;
  append(json{{"held_by_host", why}}.dump(), true);
}

void Journal::note(const std::string& event) { append(json{{"note", event}}.dump(), false); }

void Journal::completed(std::uint32_t executed_line) {
  progress_.completed = true;
  progress_.executed_line = executed_line;
  append(json{{"completed", executed_line}}.dump(), true);
}

}  // namespace hybridctl::drivers
