#include "drivers/socketcand_transport.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace hybridctl::drivers {

namespace can = protocol::can;
using Kind = TransportError::Kind;

namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool all_digits(std::string_view s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

std::string show(const std::vector<std::string>& words) {
  std::string s = "<";
  for (const auto& w : words) s += " " + w;
  return s + " >";
}

// Milliseconds from now until `deadline`, rounded up, for poll(); 0 when it passed.
int poll_ms(SteadyTime deadline) {
  const auto now = SteadyClock::now();
  if (deadline <= now) return 0;
  const auto us = std::chrono::duration_cast<std::chrono::microseconds>(deadline - now).count();
  return static_cast<int>(std::min<long long>((us + 999) / 1000, 1'000'000));
}

}  // namespace

// ---- the reader ----

void SocketcandReader::feed(std::string_view bytes) {
  if (pos_ > 0 && pos_ >= buffer_.size() / 2) {
    buffer_.erase(0, pos_);
    pos_ = 0;
  }
  buffer_.append(bytes);
}

std::optional<std::vector<std::string>> SocketcandReader::next() {
  while (true) {
    const std::size_t open = buffer_.find('<', pos_);
    if (open == std::string::npos) {
      garbage_bytes_ += buffer_.size() - pos_;
      buffer_.clear();
      pos_ = 0;
      return std::nullopt;
    }
    garbage_bytes_ += open - pos_;
    pos_ = open;
    const std::size_t close = buffer_.find('>', open + 1);
    const std::size_t reopen = buffer_.find('<', open + 1);
    if (reopen != std::string::npos && (close == std::string::npos || reopen < close)) {
      // "<" again before the ">": the first start was garbage (a damaged element).
      garbage_bytes_ += reopen - open;
      pos_ = reopen;
      continue;
    }
    if (close == std::string::npos) {
      if (buffer_.size() - open > kMaxElement) {  // no end in sight: drop it
        garbage_bytes_ += buffer_.size() - open;
        buffer_.clear();
        pos_ = 0;
      }
      return std::nullopt;
    }
    pos_ = close + 1;
    if (close - open + 1 > kMaxElement) {
      garbage_bytes_ += close - open + 1;
      continue;
    }
    std::vector<std::string> words;
    std::size_t i = open + 1;
    while (i < close) {
      while (i < close && is_space(buffer_[i])) ++i;
      std::size_t j = i;
      while (j < close && !is_space(buffer_[j])) ++j;
      if (j > i) words.emplace_back(buffer_, i, j - i);
      i = j;
    }
    return words;
  }
}

SocketcandFrame parse_socketcand_frame(std::span<const std::string> words) {
  SocketcandFrame out;
  if (words.empty() || words[0] != "frame") {
    out.error = "not a frame element";
    return out;
  }
  if (words.size() != 3 && words.size() != 4) {
    out.error = "a frame element has 3 or 4 words (frame ID SEC.USEC [DATAHEX]), this one " + std::to_string(words.size());
    return out;
  }
  const std::string& id = words[1];
  if (id.empty() || id.size() > 8) {
    out.error = "identifier '" + id + "': expected 1 to 8 hex digits";
    return out;
  }
  std::uint32_t value = 0;
  for (char c : id) {
    const int h = hex_value(c);
    if (h < 0) {
      out.error = "identifier '" + id + "': expected hex digits";
      return out;
    }
    value = value * 16 + static_cast<std::uint32_t>(h);
  }
  if (value > 0x1FFFFFFF) {
    out.error = "identifier '" + id + "' above 0x1FFFFFFF";
    return out;
  }
  const std::string& time = words[2];
  const std::size_t dot = time.find('.');
  if (dot == std::string::npos ? !all_digits(time)
                               : !all_digits(std::string_view(time).substr(0, dot)) ||
                                     !all_digits(std::string_view(time).substr(dot + 1))) {
    out.error = "time '" + time + "': expected SEC.USEC";
    return out;
  }
  const std::string data = words.size() == 4 ? words[3] : std::string();
  if (data.size() % 2 != 0 || data.size() > 16) {
    out.error = "data '" + data + "': expected 0 to 8 bytes as pairs of hex digits";
    return out;
  }
  can::CanFrame frame;
  frame.id = value;
  frame.len = static_cast<std::uint8_t>(data.size() / 2);
  for (std::size_t k = 0; k < frame.len; ++k) {
    const int hi = hex_value(data[2 * k]);
    const int lo = hex_value(data[2 * k + 1]);
    if (hi < 0 || lo < 0) {
      out.error = "data '" + data + "': expected hex digits";
      return out;
    }
    frame.data[k] = static_cast<std::uint8_t>(hi * 16 + lo);
  }
  // socketcand writes 11-bit identifiers with 3 digits and 29-bit ones with 8.
  out.extended = id.size() > 3 || value > 0x7FF;
  out.frame = frame;
  return out;
}

std::string format_socketcand_send(const can::CanFrame& frame) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%X", static_cast<unsigned>(frame.id));
  const auto bytes = frame.bytes();
  std::string s = "< send " + std::string(buf) + " " + std::to_string(bytes.size());
  for (std::uint8_t b : bytes) {
    std::snprintf(buf, sizeof buf, " %X", static_cast<unsigned>(b));
    s += buf;
  }
  return s + " >";
}

// ---- the connection ----

SocketcandIo::SocketcandIo(std::string host, int port, std::string channel)
    : host_(std::move(host)), port_(port), channel_(std::move(channel)) {}

SocketcandIo::~SocketcandIo() { close(); }

std::string SocketcandIo::describe() const {
  const bool v6 = host_.find(':') != std::string::npos;
  return "socketcand " + (v6 ? "[" + host_ + "]" : host_) + ":" + std::to_string(port_) + " channel " + channel_;
}

void SocketcandIo::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  reader_ = SocketcandReader();
  last_garbage_bytes_ = 0;
}

void SocketcandIo::open(std::chrono::milliseconds timeout) {
  close();
  timeout_ = timeout;
  const SteadyTime deadline = SteadyClock::now() + timeout;
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port_);
  if (const int rc = ::getaddrinfo(host_.c_str(), service.c_str(), &hints, &found); rc != 0)
    throw TransportError(Kind::Unreachable, describe() + ": cannot resolve " + host_ + ": " + gai_strerror(rc));
  std::string why = "no address";
  for (addrinfo* a = found; a && fd_ < 0; a = a->ai_next) {
    const int fd = ::socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) {
      why = std::strerror(errno);
      continue;
    }
    int rc = ::connect(fd, a->ai_addr, a->ai_addrlen);
    if (rc != 0 && errno == EINPROGRESS) {
      pollfd p{fd, POLLOUT, 0};
      rc = ::poll(&p, 1, poll_ms(deadline));
      if (rc == 0) {
        why = "no answer within " + std::to_string(timeout.count()) + " ms";
        ::close(fd);
        continue;
      }
      int err = 0;
      socklen_t len = sizeof err;
      ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &len);
      if (err != 0) {
        errno = err;
        rc = -1;
      } else {
        rc = 0;
      }
    }
    if (rc != 0) {
      why = std::strerror(errno);
      ::close(fd);
      continue;
    }
    int one = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    fd_ = fd;
  }
  ::freeaddrinfo(found);
  if (fd_ < 0) throw TransportError(Kind::Unreachable, describe() + ": cannot connect: " + why);

  // The handshake. A peer that answers something else is not a socketcand (or refuses
  // the channel): not worth retrying.
  auto words = expect(deadline, "connecting");
  if (words != std::vector<std::string>{"hi"})
    throw TransportError(Kind::Protocol, describe() + ": expected the greeting < hi >, got " + show(words));
  write_all("< open " + channel_ + " >");
  words = expect(deadline, "< open " + channel_ + " >");
  if (words != std::vector<std::string>{"ok"})
    throw TransportError(Kind::Protocol, describe() + ": the server refused < open " + channel_ + " >: " + show(words));
  write_all("< rawmode >");
  words = expect(deadline, "< rawmode >");
  if (words != std::vector<std::string>{"ok"})
    throw TransportError(Kind::Protocol, describe() + ": the server refused < rawmode >: " + show(words));
}

std::vector<std::string> SocketcandIo::expect(SteadyTime deadline, const std::string& after) {
  while (true) {
    if (auto words = reader_.next()) return *words;
    if (!fill(deadline) && SteadyClock::now() >= deadline)
      throw TransportError(Kind::Unreachable,
                           describe() + ": no answer to " + after + " within " + std::to_string(timeout_.count()) + " ms");
  }
}

bool SocketcandIo::fill(SteadyTime deadline) {
  if (fd_ < 0) throw TransportError(Kind::Disconnected, describe() + ": not connected");
  pollfd p{fd_, POLLIN, 0};
  const int rc = ::poll(&p, 1, poll_ms(deadline));
  if (rc < 0) {
    if (errno == EINTR) return false;
    throw TransportError(Kind::Disconnected, describe() + ": poll: " + std::strerror(errno));
  }
  if (rc == 0) return false;
  char buf[8192];
  const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
  if (n == 0) {
    close();
    throw TransportError(Kind::Disconnected, describe() + ": the server closed the connection");
  }
  if (n < 0) {
    if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) return false;
    const std::string why = std::strerror(errno);
    close();
    throw TransportError(Kind::Disconnected, describe() + ": " + why);
  }
  reader_.feed(std::string_view(buf, static_cast<std::size_t>(n)));
  return true;
}

void SocketcandIo::write_all(std::string_view text) {
  if (fd_ < 0) throw TransportError(Kind::Disconnected, describe() + ": not connected");
  const SteadyTime deadline = SteadyClock::now() + timeout_;
  while (!text.empty()) {
    const ssize_t n = ::send(fd_, text.data(), text.size(), MSG_NOSIGNAL);
    if (n > 0) {
      text.remove_prefix(static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) {
      pollfd p{fd_, POLLOUT, 0};
      if (::poll(&p, 1, poll_ms(deadline)) == 0) {
        close();
        throw TransportError(Kind::Disconnected,
                             describe() + ": the server took no data for " + std::to_string(timeout_.count()) + " ms");
      }
      continue;
    }
    const std::string why = std::strerror(errno);
    close();
    throw TransportError(Kind::Disconnected, describe() + ": " + why);
  }
}

void SocketcandIo::send(std::span<const can::CanFrame> frames) {
  std::string text;
  for (const auto& f : frames) text += format_socketcand_send(f);
  write_all(text);
}

std::optional<can::CanFrame> SocketcandIo::receive(SteadyTime deadline) {
  while (true) {
    while (auto words = reader_.next()) {
      if (reader_.garbage_bytes() != last_garbage_bytes_) {
        ++garbage_runs_;
        last_garbage_bytes_ = reader_.garbage_bytes();
      }
      if (!words->empty() && (*words)[0] == "frame") {
        const SocketcandFrame parsed = parse_socketcand_frame(*words);
        if (parsed.frame && !parsed.extended) return parsed.frame;
        if (!parsed.frame) ++bad_elements_;
        continue;  // 29-bit identifiers are not the protocol's
      }
      // `< ok >` / `< echo >` answers are harmless; anything else (an `< error >` about
      // something we sent, a damaged element) is counted.
      if (words->size() == 1 && ((*words)[0] == "ok" || (*words)[0] == "echo")) continue;
      ++bad_elements_;
    }
    if (reader_.garbage_bytes() != last_garbage_bytes_) {
      ++garbage_runs_;
      last_garbage_bytes_ = reader_.garbage_bytes();
    }
    if (!fill(deadline) && SteadyClock::now() >= deadline) return std::nullopt;
  }
}

}  // namespace hybridctl::drivers
