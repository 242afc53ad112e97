#include "config/transport_uri.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <charconv>
#include <tuple>
#include <utility>
#include <vector>

namespace hybridctl::config {

namespace {

constexpr std::string_view kTcpForm = "modbus-tcp://HOST:PORT[?unit=N]";
constexpr std::string_view kRtuForm = "modbus-rtu:///dev/DEVICE[?baud=B&parity=N|E|O&unit=N]";
constexpr std::string_view kCanForm = "socketcan://IFACE[?node=N]";
constexpr std::string_view kCandForm = "socketcand://HOST:PORT/CHANNEL[?node=N]";
constexpr std::size_t kMaxInterfaceName = 15;  // IFNAMSIZ - 1

struct Failure {
  std::string message;
};

std::string s(std::string_view v) { return std::string(v); }

std::optional<long> parse_decimal(std::string_view text) {
  if (text.empty() || text.size() > 9) return std::nullopt;
  long value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || value < 0) return std::nullopt;
  return value;
}

bool is_name_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' ||
         c == '.';
}

/// "[IPv6]:PORT" -> the address and the port's text.
std::pair<std::string_view, std::string_view> split_bracketed(std::string_view authority, std::string_view form) {
  const auto close = authority.find(']');
  if (close == std::string_view::npos) throw Failure{"unterminated '[' in the IPv6 host; expected " + s(form)};
  const auto host = authority.substr(1, close - 1);
  const auto rest = authority.substr(close + 1);
  if (rest.empty() || rest.front() != ':') throw Failure{"missing ':PORT' after the host; expected " + s(form)};
  if (host.empty() || !std::all_of(host.begin(), host.end(), [](char c) {
        return c == ':' || c == '.' || (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
      }))
    throw Failure{"bad IPv6 address '" + s(host) + "'; expected " + s(form)};
  return std::pair{host, rest.substr(1)};
}

/// HOST:PORT -> host, port. Throws Failure mentioning `form` where the form is at fault.
HostPort split_host_port(std::string_view authority, HostPortUse use, std::string_view form) {
  const bool listen = use == HostPortUse::Listen;
  const std::string listen_form = "expected " + s(form) +
                                  " with an IPv4 HOST (e.g. 127.0.0.1:1502; port 0 picks a free port)";
  std::string_view host, port;
  const bool bracketed = !listen && !authority.empty() && authority.front() == '[';
  if (bracketed) {
    std::tie(host, port) = split_bracketed(authority, form);
  } else {
    const auto colon = authority.rfind(':');
    if (colon == std::string_view::npos) throw Failure{listen ? listen_form : "missing ':PORT' after the host; expected " + s(form)};
    host = authority.substr(0, colon);
    port = authority.substr(colon + 1);
    if (host.empty()) throw Failure{listen ? listen_form : "missing host; expected " + s(form)};
    if (listen && port.empty()) throw Failure{listen_form};
  }
  HostPort out{std::string(host), 0};
  if (listen) {
    if (out.host == "localhost") out.host = "127.0.0.1";
    in_addr addr{};
    if (::inet_pton(AF_INET, out.host.c_str(), &addr) != 1)
      throw Failure{"'" + out.host + "' is not an IPv4 address (expected e.g. 127.0.0.1)"};
  } else if (!bracketed && !std::all_of(host.begin(), host.end(), is_name_char)) {
    throw Failure{"bad host name '" + s(host) + "'; expected " + s(form)};
  }
  const auto number = port.size() > (listen ? 5 : 9) ? std::nullopt : parse_decimal(port);
  if (!number || *number < (listen ? 0 : 1) || *number > 65535)
    throw Failure{listen ? "port '" + s(port) + "' is not 0..65535"
                         : "bad port '" + s(port) + "', expected 1..65535 in " + s(form)};
  out.port = static_cast<int>(*number);
  return out;
}

/// Splits "a=1&b=2" and checks keys against `allowed`; returns key -> value text in order.
std::vector<std::pair<std::string, std::string>> split_query(std::string_view query,
                                                             const std::vector<std::string_view>& allowed,
                                                             std::string_view form) {
  std::vector<std::pair<std::string, std::string>> out;
  if (query.empty()) return out;
  std::string allowed_list;
  for (auto a : allowed) allowed_list += (allowed_list.empty() ? "" : ", ") + s(a);
  while (true) {
    const auto amp = query.find('&');
    const auto part = query.substr(0, amp);
    const auto eq = part.find('=');
    if (eq == std::string_view::npos || eq == 0 || eq + 1 == part.size())
      throw Failure{"bad query parameter '" + s(part) + "', expected KEY=VALUE in " + s(form)};
    const auto key = part.substr(0, eq);
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
      throw Failure{"unknown query parameter '" + s(key) + "', expected " + allowed_list + " in " + s(form)};
    for (const auto& [k, v] : out)
      if (k == key) throw Failure{"query parameter '" + s(key) + "' given twice in " + s(form)};
    out.emplace_back(std::string(key), std::string(part.substr(eq + 1)));
    if (amp == std::string_view::npos) break;
    query.remove_prefix(amp + 1);
  }
  return out;
}

int number_parameter(const std::string& key, const std::string& value, long min, long max, std::string_view form) {
  const auto number = parse_decimal(value);
  if (!number || *number < min || *number > max)
    throw Failure{"bad " + key + " '" + value + "', expected " + std::to_string(min) + ".." + std::to_string(max) +
                  " in " + s(form)};
  return static_cast<int>(*number);
}

Transport parse_or_throw(std::string_view uri) {
  const auto scheme_end = uri.find("://");
  if (scheme_end == std::string_view::npos)
    throw Failure{"not a URI; expected one of " + s(kTransportUriForms)};
  const auto scheme = uri.substr(0, scheme_end);
  std::string_view rest = uri.substr(scheme_end + 3);
  std::string_view query;
  if (const auto q = rest.find('?'); q != std::string_view::npos) {
    query = rest.substr(q + 1);
    rest = rest.substr(0, q);
  }

  Transport t;
  t.uri = std::string(uri);
  if (scheme == "modbus-tcp") {
    t.kind = TransportKind::ModbusTcp;
    if (rest.find('/') != std::string_view::npos) throw Failure{"unexpected path; expected " + s(kTcpForm)};
    const HostPort at = split_host_port(rest, HostPortUse::Connect, kTcpForm);
    t.host = at.host;
    t.port = at.port;
    for (const auto& [k, v] : split_query(query, {"unit"}, kTcpForm)) t.unit = number_parameter(k, v, 0, 255, kTcpForm);
  } else if (scheme == "modbus-rtu") {
    t.kind = TransportKind::ModbusRtu;
    if (rest.empty() || rest.front() != '/' || rest.size() < 2 || rest.back() == '/')
      throw Failure{"expected an absolute device path as in " + s(kRtuForm)};
    t.device = std::string(rest);
    for (const auto& [k, v] : split_query(query, {"baud", "parity", "unit"}, kRtuForm)) {
      if (k == "baud") {
        const auto baud = parse_decimal(v);
        if (!baud || std::find(std::begin(kStandardBaudRates), std::end(kStandardBaudRates), *baud) ==
                         std::end(kStandardBaudRates))
          throw Failure{"bad baud '" + v +
                        "', expected a standard rate (300, 600, 1200, ... 9600, 19200, 38400, 57600, 115200, "
                        "230400, ... 4000000) in " + s(kRtuForm)};
        t.baud = static_cast<int>(*baud);
      } else if (k == "parity") {
        if (v != "N" && v != "E" && v != "O") throw Failure{"bad parity '" + v + "', expected N, E or O in " + s(kRtuForm)};
        t.parity = v[0];
      } else {
        t.unit = number_parameter(k, v, 1, 247, kRtuForm);
      }
    }
  } else if (scheme == "socketcan") {
    t.kind = TransportKind::SocketCan;
    if (rest.empty() || rest.size() > kMaxInterfaceName || !std::all_of(rest.begin(), rest.end(), is_name_char))
      throw Failure{"bad interface name '" + s(rest) + "' (1 to 15 letters, digits, '-', '_', '.'); expected " +
                    s(kCanForm)};
    t.interface_name = std::string(rest);
    for (const auto& [k, v] : split_query(query, {"node"}, kCanForm)) t.node = number_parameter(k, v, 1, 127, kCanForm);
  } else if (scheme == "socketcand") {
    t.kind = TransportKind::Socketcand;
    const auto slash = rest.find('/');
    if (slash == std::string_view::npos) throw Failure{"missing '/CHANNEL'; expected " + s(kCandForm)};
    const HostPort at = split_host_port(rest.substr(0, slash), HostPortUse::Connect, kCandForm);
    t.host = at.host;
    t.port = at.port;
    const auto channel = rest.substr(slash + 1);
    if (channel.empty() || channel.size() > kMaxInterfaceName ||
        !std::all_of(channel.begin(), channel.end(), is_name_char))
      throw Failure{"bad channel '" + s(channel) + "'; expected " + s(kCandForm)};
    t.channel = std::string(channel);
    for (const auto& [k, v] : split_query(query, {"node"}, kCandForm)) t.node = number_parameter(k, v, 1, 127, kCandForm);
  } else {
    throw Failure{"unknown scheme '" + s(scheme) + "'; expected one of " + s(kTransportUriForms)};
  }
  return t;
}

}  // namespace

HostPortResult parse_host_port(std::string_view text, HostPortUse use, std::string_view form) {
  try {
    return HostPortResult{split_host_port(text, use, form), {}};
  } catch (const Failure& f) {
    return HostPortResult{std::nullopt, f.message};
  }
}

HostPortResult parse_listen_address(std::string_view text) {
  for (std::string_view scheme : {"tcp://", "modbus-tcp://", "socketcand://"}) {
    if (text.substr(0, scheme.size()) == scheme) {
      text.remove_prefix(scheme.size());
      break;
    }
  }
  if (const auto slash = text.find('/'); slash != std::string_view::npos) text = text.substr(0, slash);  // socketcand channel
  if (const auto query = text.find('?'); query != std::string_view::npos) text = text.substr(0, query);   // ?unit=N
  return parse_host_port(text, HostPortUse::Listen, kListenAddressForm);
}

bool is_loopback_ipv4(const std::string& host) {
  in_addr addr{};
  ::inet_pton(AF_INET, host.c_str(), &addr);
  return (ntohl(addr.s_addr) >> 24) == 127;
}

TransportUriResult parse_transport_uri(std::string_view uri) {
  try {
    return TransportUriResult{parse_or_throw(uri), {}};
  } catch (const Failure& f) {
    return TransportUriResult{std::nullopt, f.message};
  }
}

}  // namespace hybridctl::config
