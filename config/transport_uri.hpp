#pragma once
// Transport URIs: how the machine file (and the command line) name a connection to a
// controller. One function, no I/O.
//
//   modbus-tcp://HOST:PORT[?unit=N]                              unit 0..255, default 1
//   modbus-rtu:///dev/DEVICE[?baud=B&parity=N|E|O&unit=N]        defaults 19200, E, 1; unit 1..247
//   socketcan://IFACE[?node=N]                                   node 1..127, default 1
//   socketcand://HOST:PORT/CHANNEL[?node=N]
//
// HOST is a name, an IPv4 address or a bracketed IPv6 address; PORT is 1..65535.
//
// The one HOST:PORT parser is here too: a transport URI's authority names a controller
// to connect to; `hybridctl sim serve` takes addresses to listen on.

#include <optional>
#include <string>
#include <string_view>

#include "config/machine.hpp"

namespace hybridctl::config {

/// The accepted forms, for messages.
inline constexpr std::string_view kTransportUriForms =
    "modbus-tcp://HOST:PORT[?unit=N], modbus-rtu:///dev/DEVICE[?baud=B&parity=N|E|O&unit=N], "
    "socketcan://IFACE[?node=N], socketcand://HOST:PORT/CHANNEL[?node=N]";

/// Baud rates accepted for modbus-rtu (the termios standard rates, 300..4000000).
inline constexpr int kStandardBaudRates[] = {300,     600,     1200,    1800,    2400,    4800,    9600,
                                             19200,   38400,   57600,   115200,  230400,  460800,  500000,
                                             576000,  921600,  1000000, 1152000, 1500000, 2000000, 2500000,
                                             3000000, 3500000, 4000000};

struct TransportUriResult {
  std::optional<Transport> transport;  ///< set on success (name left empty)
  std::string error;                   ///< otherwise: what is wrong and which form was expected
};

TransportUriResult parse_transport_uri(std::string_view uri);

/// What a HOST:PORT names, which decides what HOST and PORT may be.
enum class HostPortUse {
  Connect,  ///< a peer: HOST a name, an IPv4 address or a bracketed IPv6 address; PORT 1..65535
  Listen,   ///< a local address: HOST an IPv4 address or "localhost" (127.0.0.1); PORT 0..65535, 0 any free port
};

struct HostPort {
  std::string host;  ///< IPv6 without its brackets; "localhost" as 127.0.0.1 for Listen
  int port = 0;
};

struct HostPortResult {
  std::optional<HostPort> host_port;  ///< set on success
  std::string error;                  ///< otherwise: what is wrong and which form was expected
};

/// HOST:PORT. `form` is the accepted form of the text around it, for messages.
HostPortResult parse_host_port(std::string_view text, HostPortUse use, std::string_view form);

/// The accepted forms of parse_listen_address, for messages.
inline constexpr std::string_view kListenAddressForm = "[tcp://]HOST:PORT";

/// A listen address as `hybridctl sim serve` takes it: HOST:PORT (Listen), optionally as a
/// tcp://, modbus-tcp:// or socketcand:// URI whose /CHANNEL and ?query are ignored.
HostPortResult parse_listen_address(std::string_view text);

/// Whether an IPv4 address lies in 127.0.0.0/8.
bool is_loopback_ipv4(const std::string& host);

}  // namespace hybridctl::config
