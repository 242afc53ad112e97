// open_transport: the backend for a transport URI (docs/drivers.md).

#include "drivers/transport.hpp"

#include "common/error.hpp"
#include "config/transport_uri.hpp"
#include "drivers/can_link.hpp"
#include "drivers/modbus_transport.hpp"
#include "drivers/socketcan_transport.hpp"
#include "drivers/socketcand_transport.hpp"

namespace hybridctl::drivers {

std::string_view to_string(TransportError::Kind kind) {
  switch (kind) {
    case TransportError::Kind::Unreachable: return "unreachable";
    case TransportError::Kind::Timeout: return "timeout";
    case TransportError::Kind::Disconnected: return "disconnected";
    case TransportError::Kind::Protocol: return "protocol";
    case TransportError::Kind::Unsupported: return "unsupported";
  }
  return "unknown";
}

std::unique_ptr<Transport> open_transport(const config::Transport& where, const TransportOptions& options) {
  switch (where.kind) {
    case config::TransportKind::ModbusTcp:
    case config::TransportKind::ModbusRtu:
      return std::make_unique<ModbusTransport>(where, options);
    case config::TransportKind::Socketcand:
      return std::make_unique<CanTransport>(std::make_unique<SocketcandIo>(where.host, where.port, where.channel),
                                            static_cast<std::uint8_t>(where.node), options);
    case config::TransportKind::SocketCan:
      return std::make_unique<CanTransport>(
          std::make_unique<SocketCanIo>(where.interface_name, static_cast<std::uint8_t>(where.node)),
          static_cast<std::uint8_t>(where.node), options);
  }
  throw InputError("transport " + where.uri + ": unknown kind");
}

std::unique_ptr<Transport> open_transport(const std::string& uri, const TransportOptions& options) {
  auto parsed = config::parse_transport_uri(uri);
  if (!parsed.transport) throw InputError("transport URI '" + uri + "': " + parsed.error);
  parsed.transport->uri = uri;
  return open_transport(*parsed.transport, options);
}

}  // namespace hybridctl::drivers
