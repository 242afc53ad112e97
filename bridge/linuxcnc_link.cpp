#include "bridge/linuxcnc_link.hpp"

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdint>
#include <cstring>

#include <fcntl.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "bridge/linuxcnc_agent_script.hpp"  // generated from linuxcnc_agent.py (bridge/CMakeLists.txt)

namespace hybridctl::bridge {
namespace {

using nlohmann::json;

template <class T>
T field(const json& j, const char* name) {
  const auto it = j.find(name);
  if (it == j.end()) throw LinkError(std::string("LinuxCNC agent: status without \"") + name + "\"");
  try {
    return it->get<T>();
  } catch (const json::exception& e) {
    throw LinkError(std::string("LinuxCNC agent: status field \"") + name + "\": " + e.what());
  }
}

json parse_reply(const std::string& reply) {
  json j = json::parse(reply, nullptr, false);
  if (j.is_discarded() || !j.is_object()) throw LinkError("LinuxCNC agent: not a JSON object: " + reply.substr(0, 200));
  return j;
}

// The request number a reply carries back; 0 when it carries none.
std::uint64_t reply_id(const std::string& reply) {
  const json j = json::parse(reply, nullptr, false);
  if (!j.is_object()) return 0;
  const auto it = j.find("id");
  return it != j.end() && it->is_number_unsigned() ? it->get<std::uint64_t>() : 0;
}

}  // namespace

LinuxcncStatus parse_status(const std::string& reply) {
  const json j = parse_reply(reply);
  if (!j.value("ok", false)) throw LinkError("LinuxCNC agent: " + j.value("error", std::string("status refused")));
  LinuxcncStatus s;
  s.connected = field<bool>(j, "connected");
  if (!s.connected) {
    s.why = j.value("why", std::string("LinuxCNC does not answer"));
    return s;
  }
  s.ini = field<std::string>(j, "ini");
  s.estop = field<bool>(j, "estop");
  s.enabled = field<bool>(j, "enabled");
  s.homed = field<bool>(j, "homed");
  s.task_state = field<int>(j, "task_state");
  s.task_mode = field<int>(j, "task_mode");
  s.interp_state = field<int>(j, "interp_state");
  s.exec_state = field<int>(j, "exec_state");
  s.paused = field<bool>(j, "paused");
  s.file = field<std::string>(j, "file");
  s.motion_line = field<int>(j, "motion_line");
  s.current_line = field<int>(j, "current_line");
  s.queue = field<int>(j, "queue");
  s.inpos = field<bool>(j, "inpos");
  const auto position = field<std::vector<double>>(j, "position");
  if (position.size() != 3) throw LinkError("LinuxCNC agent: status position has " + std::to_string(position.size()) + " axes, expected 3");
  for (std::size_t a = 0; a < 3; ++a) s.position[a] = position[a];
  s.tool = field<int>(j, "tool");
  s.spindle_speed = field<double>(j, "spindle_speed");
  s.spindle_direction = field<int>(j, "spindle_direction");
  const auto dout = field<std::vector<bool>>(j, "dout");
  for (std::size_t k = 0; k < s.dout.size() && k < dout.size(); ++k) s.dout[k] = dout[k];
  s.feedrate = field<double>(j, "feedrate");
  for (const json& m : field<json>(j, "messages"))
    s.messages.push_back({m.value("error", false), m.value("text", std::string())});
  return s;
}

LinuxcncLink::LinuxcncLink(Options options) : options_(std::move(options)) {
  int in[2], out[2];
  if (pipe2(in, O_CLOEXEC) != 0 || pipe2(out, O_CLOEXEC) != 0)
    throw LinkError(std::string("cannot create pipes for the LinuxCNC agent: ") + std::strerror(errno));
  std::signal(SIGPIPE, SIG_IGN);  // a dead agent shows as a failed write, not a signal
  child_ = fork();
  if (child_ < 0) throw LinkError(std::string("cannot start the LinuxCNC agent: ") + std::strerror(errno));
  if (child_ == 0) {
    dup2(in[0], STDIN_FILENO);
    dup2(out[1], STDOUT_FILENO);
    execl(options_.python.c_str(), options_.python.c_str(), "-u", "-c", kLinuxcncAgentScript, static_cast<char*>(nullptr));
    const std::string why = "hybridctl bridge: cannot run " + options_.python + ": " + std::strerror(errno) + "\n";
    (void)!write(STDERR_FILENO, why.data(), why.size());
    _exit(127);
  }
  close(in[0]);
  close(out[1]);
  to_child_ = in[1];
  from_child_ = out[0];
}

LinuxcncLink::~LinuxcncLink() {
  if (to_child_ >= 0) close(to_child_);  // end of input: the agent returns
  if (from_child_ >= 0) close(from_child_);
  if (child_ > 0) {
    for (int i = 0; i < 100; ++i) {
      if (waitpid(child_, nullptr, WNOHANG) == child_) return;
      usleep(10'000);
    }
    kill(child_, SIGKILL);
    waitpid(child_, nullptr, 0);
  }
}

std::string LinuxcncLink::request(const std::string& json_line) {
  // Numbered: a reply that comes after its request timed out is read and dropped here,
  // not taken for the answer to the next request.
  const std::uint64_t id = ++last_id_;
  const std::string line = json_line.substr(0, json_line.rfind('}')) + ",\"id\":" + std::to_string(id) + "}\n";
  for (std::size_t sent = 0; sent < line.size();) {
    const ssize_t n = write(to_child_, line.data() + sent, line.size() - sent);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw LinkError("the LinuxCNC agent exited (is /usr/bin/python3's `linuxcnc` module installed?)");
    sent += std::size_t(n);
  }
  const auto deadline = std::chrono::steady_clock::now() + options_.reply_timeout;
  for (;;) {
    const std::size_t end = buffered_.find('\n');
    if (end != std::string::npos) {
      std::string reply = buffered_.substr(0, end);
      buffered_.erase(0, end + 1);
      if (reply_id(reply) == id) return reply;
      continue;  // the late reply to an earlier request
    }
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) throw LinkError("the LinuxCNC agent did not answer " + json_line + " within " +
                                           std::to_string(options_.reply_timeout.count()) + " ms");
    pollfd p{from_child_, POLLIN, 0};
    if (poll(&p, 1, int(left.count())) < 0 && errno != EINTR)
      throw LinkError(std::string("waiting for the LinuxCNC agent: ") + std::strerror(errno));
    if (!(p.revents & (POLLIN | POLLHUP))) continue;
    char chunk[4096];
    const ssize_t n = read(from_child_, chunk, sizeof chunk);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw LinkError("the LinuxCNC agent exited (is /usr/bin/python3's `linuxcnc` module installed?)");
    buffered_.append(chunk, std::size_t(n));
  }
}

void LinuxcncLink::act(const std::string& json_line) {
  const json reply = parse_reply(request(json_line));
  if (!reply.value("ok", false)) throw LinkError(reply.value("error", std::string("LinuxCNC refused ") + json_line));
}

LinuxcncStatus LinuxcncLink::status() { return parse_status(request(R"({"op":"status"})")); }

void LinuxcncLink::prepare(double feed_override) {
  act(json{{"op", "prepare"}, {"feed_override", feed_override}}.dump());
}

void LinuxcncLink::run(const std::string& file) { act(json{{"op", "run"}, {"file", file}}.dump()); }
void LinuxcncLink::pause() { act(R"({"op":"pause"})"); }
void LinuxcncLink::resume() { act(R"({"op":"resume"})"); }
void LinuxcncLink::abort() { act(R"({"op":"abort"})"); }

}  // namespace hybridctl::bridge
