#include "sim/wire/socketcand_server.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <deque>
#include <vector>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include "common/error.hpp"
#include "sim/controller.hpp"

namespace hybridctl::sim::wire {

namespace can = protocol::can;

// ---------------------------------------------------------------- text protocol

namespace {

constexpr std::size_t kMaxElement = 256;  // the longest valid element is ~45 characters

std::vector<std::string_view> split_words(std::string_view text) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    std::size_t j = i;
    while (j < text.size() && !std::isspace(static_cast<unsigned char>(text[j]))) ++j;
    if (j > i) words.push_back(text.substr(i, j - i));
    i = j;
  }
  return words;
}

// Hex digits only, at most `max_digits`; false otherwise.
bool parse_hex(std::string_view word, std::size_t max_digits, std::uint32_t& value) {
  if (word.empty() || word.size() > max_digits) return false;
  value = 0;
  for (char c : word) {
    int d;
    if (c >= '0' && c <= '9') d = c - '0';
    else if (c >= 'a' && c <= 'f') d = c - 'a' + 10;
    else if (c >= 'A' && c <= 'F') d = c - 'A' + 10;
    else return false;
    value = value * 16 + static_cast<std::uint32_t>(d);
  }
  return true;
}

// Text safe to quote inside "< error ... >": printable, no angle brackets, bounded.
std::string quote(std::string_view text) {
  std::string out;
  for (char c : text.substr(0, 40)) {
    const auto u = static_cast<unsigned char>(c);
    out += (u < 0x20 || u > 0x7E || c == '<' || c == '>') ? '?' : c;
  }
  if (text.size() > 40) out += "...";
  return out;
}

bool valid_channel(std::string_view name) {
  if (name.empty() || name.size() > 15) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '-';
  });
}

}  // namespace

std::size_t split_socketcand_stream(std::string_view in, std::size_t max_element,
                                   const std::function<bool(const SocketcandPiece&)>& on_piece) {
  using K = SocketcandPiece::Kind;
  std::size_t i = 0;
  while (i < in.size()) {
    if (std::isspace(static_cast<unsigned char>(in[i]))) {
      ++i;
      continue;
    }
    SocketcandPiece piece{K::Element, {}};
    std::size_t next = 0;
    if (in[i] != '<') {
      const std::size_t lt = in.find('<', i);
      next = lt == std::string_view::npos ? in.size() : lt;
      piece = {K::Garbage, in.substr(i, next - i)};
    } else {
      const std::size_t close = in.find('>', i);
      const std::size_t nested = in.find('<', i + 1);
      if (nested != std::string_view::npos && (close == std::string_view::npos || nested < close)) {
        next = nested;
        piece = {K::Unclosed, in.substr(i, nested - i)};
      } else if (close == std::string_view::npos) {
        if (in.size() - i <= max_element) return i;  // wait for the rest
        next = in.size();
        piece = {K::Overlong, in.substr(i)};
      } else {
        next = close + 1;
        piece = {K::Element, in.substr(i, next - i)};
      }
    }
    i = next;
    if (!on_piece(piece)) return i;
  }
  return i;
}

SocketcandParse parse_socketcand_element(std::string_view element) {
  SocketcandParse out;
  if (element.size() < 2 || element.front() != '<' || element.back() != '>') {
    out.error = "expected an element between angle brackets";
    return out;
  }
  const auto words = split_words(element.substr(1, element.size() - 2));
  if (words.empty()) {
    out.error = "empty element, expected a command (open, rawmode, bcmmode, echo, send)";
    return out;
  }
  const std::string_view cmd = words[0];
  auto no_args = [&](SocketcandRequest::Kind kind) {
    if (words.size() != 1) {
      out.error = std::string(cmd) + " takes no arguments";
    } else {
      out.request = SocketcandRequest{kind, {}, {}};
    }
    return out;
  };
  if (cmd == "open") {
    if (words.size() != 2 || !valid_channel(words[1])) {
      out.error = "expected 'open CHANNEL' with a bus name of 1-15 letters, digits, '_', '.' or '-'";
      return out;
    }
    out.request = SocketcandRequest{SocketcandRequest::Kind::Open, std::string(words[1]), {}};
    return out;
  }
  if (cmd == "rawmode") return no_args(SocketcandRequest::Kind::RawMode);
  if (cmd == "bcmmode") return no_args(SocketcandRequest::Kind::BcmMode);
  if (cmd == "echo") return no_args(SocketcandRequest::Kind::Echo);
  if (cmd == "send") {
    std::uint32_t id = 0, len = 0;
    if (words.size() < 3 || !parse_hex(words[1], 8, id) || id > 0x1FFFFFFF) {
      out.error = "expected 'send ID LEN B0 ...' with ID hex up to 1FFFFFFF";
      return out;
    }
    if (!parse_hex(words[2], 1, len) || len > 8) {
      out.error = "send " + quote(words[1]) + ": length '" + quote(words[2]) + "' is not 0..8";
      return out;
    }
    if (words.size() != 3 + len) {
      out.error = "send " + quote(words[1]) + ": length " + std::to_string(len) + " but " +
                  std::to_string(words.size() - 3) + " data bytes";
      return out;
    }
    can::CanFrame frame;
    frame.id = id;
    frame.len = static_cast<std::uint8_t>(len);
    for (std::uint32_t i = 0; i < len; ++i) {
      std::uint32_t b = 0;
      if (!parse_hex(words[3 + i], 2, b)) {
        out.error = "send " + quote(words[1]) + ": data byte " + std::to_string(i) + " '" + quote(words[3 + i]) +
                    "' is not 1-2 hex digits";
        return out;
      }
      frame.data[i] = static_cast<std::uint8_t>(b);
    }
    out.request = SocketcandRequest{SocketcandRequest::Kind::Send, {}, frame};
    return out;
  }
  out.error = "unknown command '" + quote(cmd) + "', expected open, rawmode, bcmmode, echo or send";
  return out;
}

std::string format_socketcand_frame(const can::CanFrame& frame, long sec, long usec) {
  char head[64];
  std::snprintf(head, sizeof head, frame.id > 0x7FF ? "< frame %08X %ld.%06ld " : "< frame %03X %ld.%06ld ",
                static_cast<unsigned>(frame.id), sec, usec);
  std::string out = head;
  static constexpr char kHex[] = "0123456789ABCDEF";
  for (std::uint8_t b : frame.bytes()) {
    out += kHex[b >> 4];
    out += kHex[b & 0xF];
  }
  out += " >";
  return out;
}

// ---------------------------------------------------------------- server

namespace {

enum class Mode { NoBus, Bcm, Raw };

struct Client {
  int fd = -1;
  Mode mode = Mode::NoBus;
  SteadyTime frames_from{};  // raw mode: frames are delivered from this time on
  std::string in;
  std::string out;
  std::uint32_t errors_in_row = 0;
  bool closing = false;  // close once `out` is written (or at once if it cannot be)
};

struct BusFrame {
  CanMicros due{0};
  can::CanFrame frame;
  int from_fd = -1;  // the client that sent it (not echoed back to it); -1: the node
};

CanMicros to_micros(SteadyTime t) { return std::chrono::duration_cast<CanMicros>(t.time_since_epoch()); }
SteadyTime to_steady(CanMicros t) { return SteadyTime(std::chrono::duration_cast<SteadyClock::duration>(t)); }

}  // namespace

struct SocketcandServer::Impl {
  Impl(protocol::ControllerPort& controller, SocketcandOptions opts)
      : options(std::move(opts)), node(controller, options.node), faults(options.faults), bus(options.bitrate) {}

  SocketcandOptions options;
  CanNode node;
  FaultInjector faults;
  CanBusClock bus;
  SocketcandCounters counters;
  std::string address;
  int port = 0;
  int listen_fd = -1;
  std::vector<Client> clients;
  std::deque<BusFrame> to_node;   // host frames on their way to the node, by due time
  std::deque<BusFrame> to_hosts;  // frames on their way to the raw-mode clients, by due time
  CanMicros last_delayed_due{0};  // with --delay-ms: when the node's latest frame arrives

  Client* find(int fd) {
    for (auto& c : clients)
      if (c.fd == fd) return &c;
    return nullptr;
  }

  void queue_text(Client& c, std::string_view text) {
    c.out.append(text.data(), text.size());
    if (c.out.size() > options.max_output_bytes && !c.closing) {
      ++counters.slow_disconnects;
      c.closing = true;
      c.out.clear();
    }
  }

  // Frames due by `now` queued, then every client's output written; a client whose socket
  // failed is closed.
  void pump_and_flush(SteadyTime now) {
    pump(now);
    for (std::size_t i = 0; i < clients.size();) {
      if (!flush(clients[i])) {
        close_client(i);
        continue;
      }
      ++i;
    }
  }

  void error(Client& c, const std::string& what) {
    queue_text(c, "< error " + what + " >");
    ++counters.errors_sent;
    if (++c.errors_in_row >= options.max_errors && !c.closing) {
      ++counters.garbage_disconnects;
      c.closing = true;
    }
  }

  static bool first_frame(const can::CanFrame& f, std::uint8_t node_id) {
    return f.id == can::data_id(node_id) && f.len >= 1 && f.len <= 8 && (f.data[0] >> 4) == 1;
  }

  void handle(Client& c, const SocketcandRequest& r, CanMicros now) {
    using K = SocketcandRequest::Kind;
    switch (r.kind) {
      case K::Open:
        if (c.mode != Mode::NoBus) {
          error(c, "a bus is already open");
          return;
        }
        c.mode = Mode::Bcm;
        queue_text(c, "< ok >");
        break;
      case K::RawMode:
      case K::BcmMode: {
        const bool raw = r.kind == K::RawMode;
        if (c.mode == Mode::NoBus) {
          error(c, std::string(raw ? "rawmode" : "bcmmode") + " before 'open CHANNEL'");
          return;
        }
        c.mode = raw ? Mode::Raw : Mode::Bcm;
        if (raw) c.frames_from = SteadyClock::now() + options.raw_settle;
        queue_text(c, "< ok >");
        break;
      }
      case K::Echo:
        queue_text(c, "< echo >");
        break;
      case K::Send: {
        if (c.mode == Mode::NoBus) {
          error(c, "send before 'open CHANNEL'");
          return;
        }
        ++counters.frames_from_hosts;
        if (faults.drop_request()) {  // injected: the connection goes, the frame with it
          c.closing = true;
          c.out.clear();
          return;
        }
        const CanMicros due = bus.reserve(now, r.frame.len);
        to_node.push_back({due, r.frame, c.fd});
        insert_to_hosts({due, r.frame, c.fd});
        break;
      }
    }
    c.errors_in_row = 0;
  }

  void insert_to_hosts(BusFrame f) {
    auto at = std::upper_bound(to_hosts.begin(), to_hosts.end(), f.due,
                               [](CanMicros due, const BusFrame& b) { return due < b.due; });
    to_hosts.insert(at, f);
  }

  // Takes every whole element out of c.in.
  void parse_input(Client& c, CanMicros now) {
    using K = SocketcandPiece::Kind;
    const std::size_t used = split_socketcand_stream(c.in, kMaxElement, [&](const SocketcandPiece& piece) {
      switch (piece.kind) {
        case K::Element: {
          const SocketcandParse p = parse_socketcand_element(piece.text);
          if (p.request) {
            handle(c, *p.request, now);
          } else {
            error(c, p.error);
          }
          break;
        }
        case K::Garbage:  // one error for the run
          error(c, "unexpected text '" + quote(piece.text) + "' outside an element, expected an element between angle brackets");
          break;
        case K::Unclosed:
          error(c, "element '" + quote(piece.text) + "' is not closed before the next one opens");
          break;
        case K::Overlong:
          error(c, "element longer than " + std::to_string(kMaxElement) + " characters without its end");
          break;
      }
      return !c.closing;
    });
    c.in.erase(0, used);
  }

  void deliver(const BusFrame& f, SteadyTime now) {
    timeval tv{};
    ::gettimeofday(&tv, nullptr);
    const std::string text = format_socketcand_frame(f.frame, tv.tv_sec, tv.tv_usec);
    for (auto& c : clients) {
      if (c.mode != Mode::Raw || c.closing || c.fd == f.from_fd || now < c.frames_from) continue;
      ++counters.frames_to_hosts;
      if (faults.corrupt_reply()) {
        std::string bad = text;
        bad[4] = '@';  // "< fr@me ...": not a frame element any more
        queue_text(c, bad);
      } else {
        queue_text(c, text);
      }
    }
  }

  // Moves frames along the bus up to `now`. The node takes each frame, and answers it, at
  // the moment the frame ends on the modelled bus (its due time), however late this loop
  // got to it: the simulator's own scheduling delays do not idle the bus.
  void pump(SteadyTime now) {
    const CanMicros t = to_micros(now);
    while (!to_node.empty() && to_node.front().due <= t) {
      const BusFrame f = to_node.front();
      to_node.pop_front();
      if (first_frame(f.frame, node.node()) && faults.refuse_request()) {
        node.refuse_transfer(f.frame);
      } else {
        node.on_frame(f.frame, f.due);
      }
      put_node_frames_on_bus(f.due);
    }
    node.tick(t);
    put_node_frames_on_bus(t);
    while (!to_hosts.empty() && to_hosts.front().due <= t) {
      deliver(to_hosts.front(), now);
      to_hosts.pop_front();
    }
  }

  // The node's outbox onto the bus, from `at` on (each frame after the one before).
  void put_node_frames_on_bus(CanMicros at) {
    auto& outbox = node.outbox();
    while (!outbox.empty()) {
      const can::CanFrame frame = outbox.front();
      outbox.pop_front();
      CanMicros due = bus.reserve(at, frame.len);
      if (faults.delays()) {
        // Late, but in order: a bus never reorders one sender's frames (random delays
        // would, and every status snapshot would arrive scrambled).
        due = std::max(due + std::chrono::duration_cast<CanMicros>(faults.reply_delay()), last_delayed_due);
        last_delayed_due = due;
      }
      insert_to_hosts({due, frame, -1});
    }
  }

  // Writes what it can; false when the client is to be closed now.
  bool flush(Client& c) {
    while (!c.out.empty()) {
      const ssize_t n = ::send(c.fd, c.out.data(), c.out.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
      if (n < 0) {
        // Not writable now: the rest waits for POLLOUT, unless the client is being closed.
        if (errno == EAGAIN || errno == EWOULDBLOCK) return !c.closing;
        return false;
      }
      c.out.erase(0, static_cast<std::size_t>(n));
    }
    return !c.closing;
  }

  void close_client(std::size_t i) {
    ::close(clients[i].fd);
    clients.erase(clients.begin() + static_cast<std::ptrdiff_t>(i));
    ++counters.disconnects;
  }

  void accept_clients() {
    for (;;) {
      const int fd = ::accept4(listen_fd, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
      if (fd < 0) return;
      if (clients.size() >= options.max_clients) {
        ::close(fd);
        ++counters.refused_connections;
        continue;
      }
      const int one = 1;
      ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
      Client c;
      c.fd = fd;
      queue_text(c, "< hi >");
      clients.push_back(std::move(c));
      ++counters.connections;
      flush(clients.back());
    }
  }
};

SocketcandServer::SocketcandServer(protocol::ControllerPort& controller, const std::string& address, int port,
                                   SocketcandOptions options)
    : impl_(std::make_unique<Impl>(controller, std::move(options))) {
  Impl& s = *impl_;
  const std::string where = "socketcand " + address + ":" + std::to_string(port);
  if (!can::valid_node(s.options.node.node)) {
    throw InputError(where + ": node " + std::to_string(s.options.node.node) + " is not 1..127");
  }
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  if (::inet_pton(AF_INET, address.c_str(), &addr.sin_addr) != 1) {
    throw InputError(where + ": '" + address + "' is not an IPv4 address (expected e.g. 127.0.0.1)");
  }
  if (port < 0 || port > 65535) throw InputError(where + ": port must be 0..65535 (0: any free port)");
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  s.listen_fd = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (s.listen_fd < 0) throw InputError(where + ": socket: " + std::strerror(errno));
  const int one = 1;
  ::setsockopt(s.listen_fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  if (::bind(s.listen_fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
      ::listen(s.listen_fd, static_cast<int>(s.options.max_clients)) != 0) {
    const int err = errno;
    ::close(s.listen_fd);
    throw InputError(where + ": cannot listen: " + std::strerror(err));
  }
  sockaddr_in bound{};
  socklen_t len = sizeof bound;
  ::getsockname(s.listen_fd, reinterpret_cast<sockaddr*>(&bound), &len);
  s.address = address;
  s.port = ntohs(bound.sin_port);
}

SocketcandServer::~SocketcandServer() {
  for (const auto& c : impl_->clients) ::close(c.fd);
  ::close(impl_->listen_fd);
}

const std::string& SocketcandServer::address() const { return impl_->address; }
int SocketcandServer::port() const { return impl_->port; }
std::size_t SocketcandServer::client_count() const { return impl_->clients.size(); }
const SocketcandCounters& SocketcandServer::counters() const { return impl_->counters; }
const CanNodeCounters& SocketcandServer::node_counters() const { return impl_->node.counters(); }
const FaultCounters& SocketcandServer::faults() const { return impl_->faults.counters(); }

void SocketcandServer::collect(std::vector<pollfd>& fds) {
  fds.push_back({impl_->listen_fd, POLLIN, 0});
  for (const auto& c : impl_->clients) {
    fds.push_back({c.fd, static_cast<short>((c.closing ? 0 : POLLIN) | (c.out.empty() ? 0 : POLLOUT)), 0});
  }
}

void SocketcandServer::service(std::span<const pollfd> fds, SteadyTime now) {
  Impl& s = *impl_;
  const CanMicros t = to_micros(now);
  for (std::size_t k = 1; k < fds.size(); ++k) {
    Client* c = s.find(fds[k].fd);
    if (!c) continue;
    if (fds[k].revents & (POLLIN | POLLHUP | POLLERR)) {
      char buffer[4096];
      const ssize_t n = ::recv(c->fd, buffer, sizeof buffer, MSG_DONTWAIT);
      if (n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) {
        c->closing = true;
        c->out.clear();
      } else if (n > 0) {
        c->in.append(buffer, static_cast<std::size_t>(n));
        s.parse_input(*c, t);
      }
    }
  }
  if (!fds.empty() && (fds[0].revents & POLLIN)) s.accept_clients();
  // Frames that are due now (all of them without pacing) go at once, not at the next tick.
  s.pump_and_flush(now);
}

void SocketcandServer::tick(SteadyTime now) {
  Impl& s = *impl_;
  s.pump_and_flush(now);
}

SteadyTime SocketcandServer::next_deadline() const {
  const Impl& s = *impl_;
  CanMicros t = s.node.next_deadline();
  if (!s.to_node.empty()) t = std::min(t, s.to_node.front().due);
  if (!s.to_hosts.empty()) t = std::min(t, s.to_hosts.front().due);
  return to_steady(t);
}

}  // namespace hybridctl::sim::wire
