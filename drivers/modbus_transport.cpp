#include "drivers/modbus_transport.hpp"

#include <modbus/modbus.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <functional>
#include <optional>
#include <string_view>
#include <thread>
#include <vector>

#include "common/error.hpp"
#include "config/transport_uri.hpp"
#include "drivers/backoff.hpp"
#include "protocol/modbus_map.hpp"

namespace hybridctl::drivers {
namespace {

namespace mb = protocol::modbus;
using Kind = TransportError::Kind;
using std::chrono::milliseconds;

// What one failed request tells the retry loop.
enum class Recovery {
  Resend,       // resend as is (a transient exception: busy, server failure)
  Resync,       // the reply stream may be out of step: TCP reconnects, RTU flushes; resend
  Reconnect,    // the connection is gone: reconnect with backoff; resend
  GiveUp,       // resending the same request cannot help
};

struct Issue {
  Kind kind;
  Recovery recovery;
  std::string message;
};

bool is_exception(int err) { return err >= EMBXILFUN && err <= EMBXGTAR; }

// Sorts a libmodbus failure (errno after a call returned -1) into what to do next.
Issue classify(int err) {
  std::string text = modbus_strerror(err);
  if (err == ETIMEDOUT) return {Kind::Timeout, Recovery::Resync, "no reply within the response timeout"};
  if (err == EMBXILFUN || err == EMBXILADD || err == EMBXILVAL) {
    const int code = err - MODBUS_ENOBASE;
    return {Kind::Protocol, Recovery::GiveUp,
            "the controller answered exception " + std::string(code < 10 ? "0" : "") + std::to_string(code) + " (" + text +
                "): it does not serve this request (not a controller of the program-stream protocol, or another "
                "protocol version?)"};
  }
  if (is_exception(err)) {
    const int code = err - MODBUS_ENOBASE;
    return {Kind::Protocol, Recovery::Resend,
            "the controller answered exception " + std::string(code < 10 ? "0" : "") + std::to_string(code) + " (" + text + ")"};
  }
  if (err == EMBBADCRC || err == EMBBADDATA || err == EMBBADEXC || err == EMBUNKEXC || err == EMBMDATA ||
      err == EMBBADSLAVE)
    return {Kind::Protocol, Recovery::Resync, "corrupt reply: " + text};
  // Everything else comes from the socket or the serial line: ECONNRESET (libmodbus's
  // word for EOF too), EPIPE, ECONNREFUSED, EBADF, EIO, ...
  return {Kind::Disconnected, Recovery::Reconnect, "connection lost: " + text};
}

std::string register_range(int address, std::size_t count) {
  return std::to_string(address) + ".." + std::to_string(address + static_cast<int>(count) - 1);
}

}  // namespace

void check_rtu_baud(int baud) {
  const auto& rates = config::kStandardBaudRates;
  if (std::find(std::begin(rates), std::end(rates), baud) == std::end(rates)) {
    std::string list;
    for (int r : rates) list += (list.empty() ? "" : ", ") + std::to_string(r);
    throw InputError("modbus-rtu: baud rate " + std::to_string(baud) +
                     " is not one libmodbus supports (it would silently use 9600); expected one of " + list);
  }
}

struct ModbusTransport::Impl {
  config::Transport where;
  TransportOptions options;
  modbus_t* ctx = nullptr;
  bool rtu = false;
  bool connected = false;
  bool ever_connected = false;
  TransportCounters counters;

  Impl(const config::Transport& w, const TransportOptions& o) : where(w), options(o) {
    if (where.kind == config::TransportKind::ModbusTcp) {
      if (where.unit < 0 || (where.unit > 247 && where.unit != 255))
        throw InputError(describe() + ": unit " + std::to_string(where.unit) +
                         " cannot be addressed: libmodbus takes units 0..247 or 255 over TCP");
      const std::string service = std::to_string(where.port);
      // The protocol-independent form resolves names and IPv6 addresses too.
      ctx = modbus_new_tcp_pi(where.host.c_str(), service.c_str());
    } else if (where.kind == config::TransportKind::ModbusRtu) {
      rtu = true;
      check_rtu_baud(where.baud);
      if (where.parity != 'N' && where.parity != 'E' && where.parity != 'O')
        throw InputError(describe() + ": parity '" + std::string(1, where.parity) + "': expected N, E or O");
      if (where.unit < 1 || where.unit > 247)
        throw InputError(describe() + ": unit " + std::to_string(where.unit) + ": expected 1..247 on a serial line");
      ctx = modbus_new_rtu(where.device.c_str(), where.baud, where.parity, 8, 1);
    } else {
      throw InputError("not a Modbus transport: " + where.uri);
    }
    if (!ctx) throw InputError(describe() + ": libmodbus refused the settings: " + modbus_strerror(errno));
    if (modbus_set_slave(ctx, where.unit) != 0) {
      const std::string why = modbus_strerror(errno);
      modbus_free(ctx);
      throw InputError(describe() + ": libmodbus refused unit " + std::to_string(where.unit) + ": " + why);
    }
    const auto timeout = std::max(options.response_timeout, milliseconds{1});
    modbus_set_response_timeout(ctx, static_cast<std::uint32_t>(timeout.count() / 1000),
                                static_cast<std::uint32_t>((timeout.count() % 1000) * 1000));
    // The byte timeout bounds the silence inside one reply; keep it no longer than the
    // response timeout so a stalled reply fails in about that time.
    const auto byte_timeout = std::min(timeout, milliseconds{500});
    modbus_set_byte_timeout(ctx, 0, static_cast<std::uint32_t>(byte_timeout.count() * 1000));
    try {
      connect();
    } catch (...) {
      modbus_free(ctx);
      throw;
    }
  }

  ~Impl() {
    if (ctx) {
      modbus_close(ctx);
      modbus_free(ctx);
    }
  }

  std::string describe() const {
    if (where.kind == config::TransportKind::ModbusRtu)
      return "modbus-rtu " + where.device + " " + std::to_string(where.baud) + " 8" + std::string(1, where.parity) +
             "1 unit " + std::to_string(where.unit);
    const bool v6 = where.host.find(':') != std::string::npos;
    return "modbus-tcp " + (v6 ? "[" + where.host + "]" : where.host) + ":" + std::to_string(where.port) + " unit " +
           std::to_string(where.unit);
  }

  void disconnect() {
    modbus_close(ctx);
    connected = false;
  }

  // Connects (or reconnects) with backoff; throws Unreachable when every attempt failed.
  void connect() {
    if (connected) return;
    Backoff backoff(options.reconnect_backoff, options.reconnect_attempts);
    while (true) {
      if (modbus_connect(ctx) == 0) {
        connected = true;
        if (ever_connected) ++counters.reconnects;
        ever_connected = true;
        return;
      }
      const std::string why = modbus_strerror(errno);
      modbus_close(ctx);
      if (!backoff.wait_after_failure())
        throw TransportError(Kind::Unreachable, describe() + ": cannot " + (rtu ? "open the serial line" : "connect") +
                                                    " (" + std::to_string(backoff.failures()) + " attempt" +
                                                    (backoff.failures() == 1 ? "" : "s") + "): " + why);
    }
  }

  // After a reply that did not parse: the rest of it may still be on its way.
  void resync() {
    if (!rtu) {
      // TCP has no frame delimiter: after a reply that did not parse, only a new
      // connection is certainly in step.
      disconnect();
      return;
    }
    // RTU: let the rest of the frame arrive (a whole 256-byte ADU at the line's rate,
    // 11 bits a character), then drop whatever is in the line.
    const auto frame_time = std::chrono::microseconds(256LL * 11 * 1'000'000 / std::max(where.baud, 1));
    std::this_thread::sleep_for(std::min<std::chrono::microseconds>(frame_time + std::chrono::milliseconds(2),
                                                                     options.response_timeout));
    modbus_flush(ctx);
  }

  // Runs `once` (one request; nullopt on success) until it succeeds, recovering from
  // failures as the header describes. `what` names the request for messages (made only
  // when one is needed: this is the hot path of streaming).
  using What = std::function<std::string()>;
  void run(const What& what, const std::function<std::optional<Issue>()>& once) {
    int resends = 0;
    while (true) {
      connect();
      ++counters.requests;
      std::optional<Issue> issue = once();
      if (!issue) return;
      switch (issue->kind) {
        case Kind::Timeout: ++counters.timeouts; break;
        case Kind::Protocol: ++counters.bad_replies; break;
        default: break;
      }
      const bool last = issue->recovery == Recovery::GiveUp || resends >= options.request_retries;
      switch (issue->recovery) {
        // After a timeout too: a late reply must not pass for the next request's. Done
        // before giving up as well, so the next call starts in step.
        case Recovery::Resync: resync(); break;
        case Recovery::Reconnect: disconnect(); break;
        case Recovery::Resend:  // a busy controller: give it a moment
          if (!last) std::this_thread::sleep_for(std::min(options.reconnect_backoff, milliseconds{100}));
          break;
        case Recovery::GiveUp: break;
      }
      if (last)
        throw TransportError(issue->kind, describe() + ": " + what() + ": " + issue->message +
                                              (resends ? " (after " + std::to_string(resends) + " resend" +
                                                             (resends == 1 ? "" : "s") + ")"
                                                       : std::string()));
      ++resends;
      ++counters.retries;
    }
  }

  // A status block read back (by FC4 or FC23): the right count and decodable.
  static std::optional<Issue> take_status(int rc, const std::vector<std::uint16_t>& regs, protocol::Status& out) {
    if (rc < 0) return classify(errno);
    if (static_cast<std::size_t>(rc) != protocol::kStatusRegisters)
      return Issue{Kind::Protocol, Recovery::Resync,
                   "the reply carries " + std::to_string(rc) + " status registers, expected " +
                       std::to_string(protocol::kStatusRegisters)};
    auto status = protocol::decode_status(std::span<const std::uint16_t>(regs.data(), protocol::kStatusRegisters));
    if (!status.ok())
      return Issue{Kind::Protocol, Recovery::Resync, "the status block does not decode: " + status.error().message};
    out = std::move(status).value();
    return std::nullopt;
  }

  // FC23: writes `values` at `address`, reads the status mirror, in one request.
  protocol::Status write_and_read_status(const What& what, int address, const std::vector<std::uint16_t>& values) {
    protocol::Status status;
    std::vector<std::uint16_t> regs(protocol::kStatusRegisters);
    run([&] {
          return what() + " (FC23 write " + register_range(address, values.size()) + ", read " +
                 register_range(mb::kStatusMirrorAddress, mb::kStatusCount) + ")";
        },
        [&]() -> std::optional<Issue> {
          const int rc = modbus_write_and_read_registers(ctx, address, static_cast<int>(values.size()), values.data(),
                                                         mb::kStatusMirrorAddress, mb::kStatusCount, regs.data());
          return take_status(rc, regs, status);
        });
    return status;
  }
};

ModbusTransport::ModbusTransport(const config::Transport& where, const TransportOptions& options)
    : impl_(std::make_unique<Impl>(where, options)) {}

ModbusTransport::~ModbusTransport() = default;

std::string ModbusTransport::describe() const { return impl_->describe(); }

std::size_t ModbusTransport::max_chunk_payload() const { return mb::kMaxChunkPayload; }

protocol::Status ModbusTransport::read_status() {
  protocol::Status status;
  std::vector<std::uint16_t> regs(protocol::kStatusRegisters);
  impl_->run([] { return "read the status (FC4 input registers " + register_range(mb::kStatusAddress, mb::kStatusCount) + ")"; },
             [&]() -> std::optional<Issue> {
               const int rc = modbus_read_input_registers(impl_->ctx, mb::kStatusAddress, mb::kStatusCount, regs.data());
               return Impl::take_status(rc, regs, status);
             });
  return status;
}

protocol::Status ModbusTransport::send_command(const protocol::Command& command) {
  const auto block = protocol::encode_command(command);
  return impl_->write_and_read_status(
      [&] { return "command " + std::string(protocol::to_string(command.code)) + " seq " + std::to_string(command.seq); },
      mb::kCommandAddress, std::vector<std::uint16_t>(block.begin(), block.end()));
}

protocol::Status ModbusTransport::send_chunk(const protocol::Chunk& chunk) {
  auto mailbox = mb::encode_mailbox(chunk, mb::kMaxChunkPayload);
  if (!mailbox.ok())
    throw InputError(describe() + ": chunk " + std::to_string(chunk.seq) + " (lines from " +
                     std::to_string(chunk.first_line) + ") cannot be sent: " + mailbox.error().message);
  return impl_->write_and_read_status([&] { return "chunk " + std::to_string(chunk.seq); }, mb::kMailboxAddress,
                                      mailbox.value());
}

void ModbusTransport::send_heartbeat(std::uint16_t counter) {
  impl_->run([] { return "heartbeat (FC6 write holding register " + std::to_string(mb::kHeartbeatAddress) + ")"; },
             [&]() -> std::optional<Issue> {
               if (modbus_write_register(impl_->ctx, mb::kHeartbeatAddress, counter) < 0) return classify(errno);
               return std::nullopt;
             });
}

TransportCounters ModbusTransport::counters() const { return impl_->counters; }

}  // namespace hybridctl::drivers
