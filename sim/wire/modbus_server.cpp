// The simulated controller's Modbus servers: see modbus_server.hpp for what they do.
// libmodbus 3.1.6 notes that shaped this file:
//  - a context is not thread-safe; one context serves every TCP client here, its socket
//    switched with modbus_set_socket() before each receive and reply (one thread);
//  - modbus_receive() frames a TCP request by its function code and ignores the MBAP
//    length, so the header is checked here after it returns;
//  - libmodbus answers some malformed requests (bad counts, unknown function codes) after
//    sleeping its response timeout and flushing the socket, which would stall every
//    client; the map check (inspect_request_pdu) answers those first, without a stall;
//  - modbus_mapping_new_start_address() takes 8 arguments in this version.

#include "sim/wire/modbus_server.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <vector>

#include <arpa/inet.h>
#include <fcntl.h>
#include <modbus/modbus.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include "common/error.hpp"
#include "protocol/messages.hpp"
#include "protocol/modbus_map.hpp"
#include "sim/controller.hpp"

namespace hybridctl::sim::wire {
namespace {

namespace mb = protocol::modbus;

constexpr int kBusyException = MODBUS_EXCEPTION_SLAVE_OR_SERVER_BUSY;  // 6
constexpr int kTcpHeaderLength = 7;                                   // MBAP
constexpr int kRtuHeaderLength = 1;                                   // address
constexpr int kRtuChecksumLength = 2;                                 // CRC-16
constexpr std::size_t kMaxAdu = 260;

std::string errno_text(int err) { return std::strerror(err); }

// What happens to a request after process().
enum class Disposition {
  Reply,    // answer (normally, or with the exception code set)
  Drop,     // injected: close the connection / stay silent
};

// The part both servers share: the register mapping, the controller calls, the reply
// construction (direct, or captured through a socket pair when a fault needs the bytes).
class ModbusCore {
 public:
  ModbusCore(protocol::ControllerPort& controller, const ModbusServerOptions& options, int header_length, int checksum_length)
      : controller_(controller), faults_(options.faults), header_length_(header_length),
        checksum_length_(checksum_length) {
    mapping_ = modbus_mapping_new_start_address(0, 0, 0, 0, 0, mb::kHoldingRegisterCount, 0, mb::kInputRegisterCount);
    if (!mapping_) throw std::runtime_error("libmodbus: cannot allocate the register mapping: " + errno_text(errno));
    if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0, capture_) != 0) {
      modbus_mapping_free(mapping_);
      throw std::runtime_error("sim: socketpair: " + errno_text(errno));
    }
    refresh();
  }
  ~ModbusCore() {
    modbus_mapping_free(mapping_);
    ::close(capture_[0]);
    ::close(capture_[1]);
  }
  ModbusCore(const ModbusCore&) = delete;
  ModbusCore& operator=(const ModbusCore&) = delete;

  // The status block and its mirror from the controller.
  void refresh() {
    const protocol::StatusRegisters regs = protocol::encode_status(controller_.status());
    std::copy(regs.begin(), regs.end(), mapping_->tab_input_registers + mb::kStatusAddress);
    std::copy(regs.begin(), regs.end(), mapping_->tab_registers + mb::kStatusMirrorAddress);
  }

  // Checks the request, applies its write, refreshes the status. `exception` is set to the
  // exception to answer with (0: a normal reply).
  Disposition process(const std::uint8_t* req, int length, int& exception) {
    ++counters_.requests;
    exception = 0;
    if (faults_.drop_request()) return Disposition::Drop;
    if (faults_.refuse_request()) {
      exception = kBusyException;
      return Disposition::Reply;
    }
    const std::size_t pdu_length = static_cast<std::size_t>(length - header_length_ - checksum_length_);
    const mb::ModbusRequestVerdict verdict =
        mb::inspect_request_pdu(std::span<const std::uint8_t>(req + header_length_, pdu_length));
    if (verdict.exception) {
      exception = static_cast<int>(*verdict.exception);
      return Disposition::Reply;
    }
    if (verdict.request) apply(verdict.target, verdict.request->values);
    refresh();
    return Disposition::Reply;
  }

  // Builds the reply with libmodbus. Sent straight to `fd` unless `capture`; then the
  // bytes are returned in `out` and nothing is sent. False when libmodbus failed (the
  // peer is gone or not reading).
  bool reply(modbus_t* ctx, int fd, const std::uint8_t* req, int length, int exception, bool capture,
             std::vector<std::uint8_t>& out) {
    modbus_set_socket(ctx, capture ? capture_[0] : fd);
    const int rc = exception ? modbus_reply_exception(ctx, req, static_cast<unsigned>(exception))
                             : modbus_reply(ctx, req, length, mapping_);
    modbus_set_socket(ctx, fd);
    if (capture) {
      out.clear();
      std::uint8_t buffer[kMaxAdu + 16];
      for (;;) {
        const ssize_t n = ::recv(capture_[1], buffer, sizeof buffer, MSG_DONTWAIT);
        if (n <= 0) break;
        out.insert(out.end(), buffer, buffer + n);
      }
    }
    if (rc < 0) return false;
    if (rc > 0) {
      ++counters_.replies;
      if (exception > 0 && exception < static_cast<int>(counters_.exceptions.size())) ++counters_.exceptions[exception];
    }
    return true;
  }

  FaultInjector& faults() { return faults_; }
  ModbusCounters& counters() { return counters_; }

 private:
  void apply(mb::WriteTarget target, const std::vector<std::uint16_t>& values) {
    switch (target) {
      case mb::WriteTarget::Heartbeat:
        ++counters_.heartbeat_writes;
        if (!values.empty()) controller_.write_heartbeat(values[0]);
        break;
      case mb::WriteTarget::Command:
        ++counters_.command_writes;
        controller_.write_command(std::span<const std::uint16_t>(values));
        break;
      case mb::WriteTarget::Mailbox:
        ++counters_.mailbox_writes;
        controller_.write_mailbox(std::span<const std::uint16_t>(values));
        break;
      case mb::WriteTarget::None:
        break;
    }
  }

  protocol::ControllerPort& controller_;
  FaultInjector faults_;
  ModbusCounters counters_;
  modbus_mapping_t* mapping_ = nullptr;
  int capture_[2] = {-1, -1};
  int header_length_;
  int checksum_length_;
};

void set_timeouts(modbus_t* ctx, std::chrono::milliseconds byte_timeout) {
  const auto us = std::chrono::duration_cast<std::chrono::microseconds>(byte_timeout).count();
  const auto sec = static_cast<std::uint32_t>(us / 1'000'000);
  const auto usec = static_cast<std::uint32_t>(us % 1'000'000);
  modbus_set_byte_timeout(ctx, sec, usec);
  // Only asked to receive when poll() saw data, so the wait for a first byte is short; and
  // libmodbus's flush-after-error sleeps the response timeout: keep it short too.
  modbus_set_indication_timeout(ctx, sec, usec);
  modbus_set_response_timeout(ctx, 0, 1000);
  modbus_set_error_recovery(ctx, MODBUS_ERROR_RECOVERY_NONE);
}

bool send_all(int fd, const std::vector<std::uint8_t>& bytes, bool socket) {
  const ssize_t n = socket ? ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL | MSG_DONTWAIT)
                           : ::write(fd, bytes.data(), bytes.size());
  return n == static_cast<ssize_t>(bytes.size());
}

}  // namespace

// ---------------------------------------------------------------- TCP

struct ModbusTcpServer::Impl {
  struct Client {
    int fd = -1;
    bool pending = false;             // a delayed reply waits to leave
    SteadyTime due{};
    std::vector<std::uint8_t> reply;
  };

  Impl(protocol::ControllerPort& controller, ModbusServerOptions opts)
      : options(std::move(opts)), core(controller, options, kTcpHeaderLength, 0) {}

  ModbusServerOptions options;
  ModbusCore core;
  std::string address;
  int port = 0;
  modbus_t* ctx = nullptr;
  int listen_fd = -1;
  std::vector<Client> clients;
  std::uint8_t query[MODBUS_TCP_MAX_ADU_LENGTH];

  void close_client(std::size_t i) {
    ::close(clients[i].fd);
    clients.erase(clients.begin() + static_cast<std::ptrdiff_t>(i));
    ++core.counters().disconnects;
  }

  // Reads and answers one request of client i. False when the client is to be closed.
  bool serve_client(Client& client, SteadyTime now) {
    modbus_set_socket(ctx, client.fd);
    const int length = modbus_receive(ctx, query);
    if (length < 0) {
      // ECONNRESET: the client closed. Anything else (stall mid-frame, too many data) is
      // a framing error: the stream cannot be resynchronised, so the client goes.
      if (errno != ECONNRESET) ++core.counters().bad_frames;
      return false;
    }
    if (length == 0) return true;
    const unsigned protocol_id = (query[2] << 8) | query[3];
    const unsigned mbap_length = (query[4] << 8) | query[5];
    if (protocol_id != 0 || mbap_length != static_cast<unsigned>(length - 6)) {
      ++core.counters().bad_frames;
      return false;
    }
    int exception = 0;
    if (core.process(query, length, exception) == Disposition::Drop) return false;
    const bool corrupt = core.faults().corrupt_reply();
    const bool delay = core.faults().delays();
    if (!corrupt && !delay) return core.reply(ctx, client.fd, query, length, exception, false, client.reply);
    if (!core.reply(ctx, client.fd, query, length, exception, true, client.reply)) return false;
    if (corrupt && client.reply.size() > 7) client.reply[7] ^= 0x40;  // the function code
    if (delay) {
      client.pending = true;
      client.due = now + core.faults().reply_delay();
      return true;
    }
    return send_all(client.fd, client.reply, true);
  }

  void accept_clients() {
    for (;;) {
      const int fd = ::accept4(listen_fd, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
      if (fd < 0) return;
      if (clients.size() >= options.max_clients || fd >= FD_SETSIZE) {
        ::close(fd);
        ++core.counters().refused_connections;
        continue;
      }
      const int one = 1;
      ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
      Client c;
      c.fd = fd;
      clients.push_back(std::move(c));
      ++core.counters().connections;
    }
  }
};

ModbusTcpServer::ModbusTcpServer(protocol::ControllerPort& controller, const std::string& address, int port,
                                 ModbusServerOptions options)
    : impl_(std::make_unique<Impl>(controller, std::move(options))) {
  Impl& s = *impl_;
  const std::string where = address + ":" + std::to_string(port);
  in_addr parsed{};
  if (::inet_pton(AF_INET, address.c_str(), &parsed) != 1) {
    throw InputError("modbus-tcp " + where + ": '" + address + "' is not an IPv4 address (expected e.g. 127.0.0.1)");
  }
  if (port < 0 || port > 65535) throw InputError("modbus-tcp " + where + ": port must be 0..65535 (0: any free port)");
  s.address = address;
  s.ctx = modbus_new_tcp(address.c_str(), port);
  if (!s.ctx) throw InputError("modbus-tcp " + where + ": " + modbus_strerror(errno));
  modbus_set_debug(s.ctx, s.options.debug ? TRUE : FALSE);
  set_timeouts(s.ctx, s.options.byte_timeout);
  s.listen_fd = modbus_tcp_listen(s.ctx, static_cast<int>(s.options.max_clients));
  if (s.listen_fd < 0) {
    const int err = errno;
    modbus_free(s.ctx);
    throw InputError("modbus-tcp " + where + ": cannot listen: " + errno_text(err));
  }
  ::fcntl(s.listen_fd, F_SETFL, ::fcntl(s.listen_fd, F_GETFL) | O_NONBLOCK);
  ::fcntl(s.listen_fd, F_SETFD, FD_CLOEXEC);
  sockaddr_in bound{};
  socklen_t len = sizeof bound;
  ::getsockname(s.listen_fd, reinterpret_cast<sockaddr*>(&bound), &len);
  s.port = ntohs(bound.sin_port);
}

ModbusTcpServer::~ModbusTcpServer() {
  Impl& s = *impl_;
  for (const auto& c : s.clients) ::close(c.fd);
  modbus_set_socket(s.ctx, -1);  // the clients are closed above; modbus_free must not close one again
  modbus_free(s.ctx);
  ::close(s.listen_fd);
}

const std::string& ModbusTcpServer::address() const { return impl_->address; }
int ModbusTcpServer::port() const { return impl_->port; }
std::size_t ModbusTcpServer::client_count() const { return impl_->clients.size(); }
const ModbusCounters& ModbusTcpServer::counters() const { return impl_->core.counters(); }
const FaultCounters& ModbusTcpServer::faults() const { return impl_->core.faults().counters(); }

void ModbusTcpServer::collect(std::vector<pollfd>& fds) {
  fds.push_back({impl_->listen_fd, POLLIN, 0});
  // A client with a reply still held back is not read (its requests stay in order); a
  // negative descriptor makes poll() skip it, hang-ups included.
  for (const auto& c : impl_->clients) fds.push_back({c.pending ? -1 : c.fd, POLLIN, 0});
}

void ModbusTcpServer::service(std::span<const pollfd> fds, SteadyTime now) {
  Impl& s = *impl_;
  for (std::size_t k = 1; k < fds.size(); ++k) {
    if (!(fds[k].revents & (POLLIN | POLLHUP | POLLERR))) continue;
    const auto it = std::find_if(s.clients.begin(), s.clients.end(), [&](const auto& c) { return c.fd == fds[k].fd; });
    if (it == s.clients.end() || it->pending) continue;
    if (!s.serve_client(*it, now)) s.close_client(static_cast<std::size_t>(it - s.clients.begin()));
  }
  if (!fds.empty() && (fds[0].revents & POLLIN)) s.accept_clients();
}

void ModbusTcpServer::tick(SteadyTime now) {
  Impl& s = *impl_;
  for (std::size_t i = 0; i < s.clients.size();) {
    auto& c = s.clients[i];
    if (c.pending && c.due <= now) {
      c.pending = false;
      if (!send_all(c.fd, c.reply, true)) {
        s.close_client(i);
        continue;
      }
    }
    ++i;
  }
}

SteadyTime ModbusTcpServer::next_deadline() const {
  SteadyTime t = SteadyTime::max();
  for (const auto& c : impl_->clients)
    if (c.pending) t = std::min(t, c.due);
  return t;
}

// ---------------------------------------------------------------- RTU

struct ModbusRtuServer::Impl {
  Impl(protocol::ControllerPort& controller, ModbusRtuSettings st, ModbusServerOptions opts)
      : settings(std::move(st)), options(std::move(opts)),
        core(controller, options, kRtuHeaderLength, kRtuChecksumLength) {}

  ModbusRtuSettings settings;
  ModbusServerOptions options;
  ModbusCore core;
  modbus_t* ctx = nullptr;
  int fd = -1;
  bool pending = false;
  SteadyTime due{};
  std::vector<std::uint8_t> reply;
  SteadyTime quiet_until{};  // after a hang-up on the line, do not poll it for a while
  std::uint8_t query[MODBUS_RTU_MAX_ADU_LENGTH];

  void serve(SteadyTime now) {
    const int length = modbus_receive(ctx, query);
    if (length < 0) {  // bad CRC, timeout inside a frame, line error
      ++core.counters().bad_frames;
      modbus_flush(ctx);
      return;
    }
    if (length == 0) {  // for another unit
      ++core.counters().other_unit;
      return;
    }
    const bool broadcast = query[0] == 0;
    if (broadcast) ++core.counters().broadcasts;
    int exception = 0;
    if (core.process(query, length, exception) == Disposition::Drop) return;  // silence
    if (broadcast) return;  // applied, never answered
    const bool corrupt = core.faults().corrupt_reply();
    const bool delay = core.faults().delays();
    if (!corrupt && !delay) {
      core.reply(ctx, fd, query, length, exception, false, reply);
      return;
    }
    if (!core.reply(ctx, fd, query, length, exception, true, reply)) return;
    if (corrupt && reply.size() >= 5) reply[reply.size() - 3] ^= 0xFF;  // the CRC no longer matches
    if (delay) {
      pending = true;
      due = now + core.faults().reply_delay();
      return;
    }
    send_all(fd, reply, false);
  }
};

ModbusRtuServer::ModbusRtuServer(protocol::ControllerPort& controller, ModbusRtuSettings settings, ModbusServerOptions options)
    : impl_(std::make_unique<Impl>(controller, std::move(settings), std::move(options))) {
  Impl& s = *impl_;
  const std::string& dev = s.settings.device;
  if (s.settings.unit < 1 || s.settings.unit > 247) {
    throw InputError("modbus-rtu " + dev + ": unit " + std::to_string(s.settings.unit) + " is not 1..247");
  }
  if (s.settings.parity != 'N' && s.settings.parity != 'E' && s.settings.parity != 'O') {
    throw InputError("modbus-rtu " + dev + ": parity must be N, E or O");
  }
  s.ctx = modbus_new_rtu(dev.c_str(), s.settings.baud, s.settings.parity, 8, 1);
  if (!s.ctx) throw InputError("modbus-rtu " + dev + ": " + modbus_strerror(errno));
  modbus_set_debug(s.ctx, s.options.debug ? TRUE : FALSE);
  set_timeouts(s.ctx, s.options.byte_timeout);
  if (modbus_set_slave(s.ctx, s.settings.unit) != 0 || modbus_connect(s.ctx) != 0) {
    const int err = errno;
    modbus_free(s.ctx);
    throw InputError("modbus-rtu " + dev + ": cannot open: " + modbus_strerror(err));
  }
  s.fd = modbus_get_socket(s.ctx);
  ::fcntl(s.fd, F_SETFD, FD_CLOEXEC);
}

ModbusRtuServer::~ModbusRtuServer() {
  modbus_close(impl_->ctx);
  modbus_free(impl_->ctx);
}

const ModbusRtuSettings& ModbusRtuServer::settings() const { return impl_->settings; }
const ModbusCounters& ModbusRtuServer::counters() const { return impl_->core.counters(); }
const FaultCounters& ModbusRtuServer::faults() const { return impl_->core.faults().counters(); }

void ModbusRtuServer::collect(std::vector<pollfd>& fds) {
  // Not read while a reply is held back, nor for a while after a hang-up (poll() would
  // report the hang-up at once, again and again): a negative descriptor is skipped.
  const bool listen = !impl_->pending && SteadyClock::now() >= impl_->quiet_until;
  fds.push_back({listen ? impl_->fd : -1, POLLIN, 0});
}

void ModbusRtuServer::service(std::span<const pollfd> fds, SteadyTime now) {
  Impl& s = *impl_;
  if (fds.empty() || s.pending) return;
  if (fds[0].revents & (POLLHUP | POLLERR)) {
    // The other end of a pty closed (or the line failed): try again a little later
    // instead of spinning on the hang-up.
    s.quiet_until = now + std::chrono::milliseconds(100);
  } else if (fds[0].revents & POLLIN) {
    s.serve(now);
  }
}

void ModbusRtuServer::tick(SteadyTime now) {
  Impl& s = *impl_;
  if (s.pending && s.due <= now) {
    s.pending = false;
    send_all(s.fd, s.reply, false);
  }
}

SteadyTime ModbusRtuServer::next_deadline() const {
  if (impl_->pending) return impl_->due;
  if (impl_->quiet_until > SteadyClock::now()) return impl_->quiet_until;
  return SteadyTime::max();
}

}  // namespace hybridctl::sim::wire
