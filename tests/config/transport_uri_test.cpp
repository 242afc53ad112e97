// Transport URIs: the four accepted forms with their defaults, and a message naming the
// expected form for each kind of mistake.

#include <gtest/gtest.h>

#include "config/transport_uri.hpp"

namespace {

using namespace hybridctl::config;

Transport ok(const std::string& uri) {
  const auto r = parse_transport_uri(uri);
  EXPECT_TRUE(r.transport.has_value()) << uri << ": " << r.error;
  return r.transport.value_or(Transport{});
}

std::string error(const std::string& uri) {
  const auto r = parse_transport_uri(uri);
  EXPECT_FALSE(r.transport.has_value()) << uri << " was accepted";
  return r.error;
}

TEST(TransportUri, ModbusTcp) {
  const Transport t = ok("modbus-tcp://127.0.0.1:1502");
  EXPECT_EQ(t.kind, TransportKind::ModbusTcp);
  EXPECT_EQ(t.host, "127.0.0.1");
  EXPECT_EQ(t.port, 1502);
  EXPECT_EQ(t.unit, 1);
  EXPECT_EQ(ok("modbus-tcp://plc.local:502?unit=17").unit, 17);
  const Transport v6 = ok("modbus-tcp://[::1]:502");
  EXPECT_EQ(v6.host, "::1");
  EXPECT_EQ(v6.port, 502);
}

TEST(TransportUri, ModbusRtu) {
  const Transport t = ok("modbus-rtu:///dev/ttyUSB0?baud=115200&parity=N&unit=3");
  EXPECT_EQ(t.kind, TransportKind::ModbusRtu);
  EXPECT_EQ(t.device, "/dev/ttyUSB0");
  EXPECT_EQ(t.baud, 115200);
  EXPECT_EQ(t.parity, 'N');
  EXPECT_EQ(t.unit, 3);
  const Transport d = ok("modbus-rtu:///dev/ttyS1");
  EXPECT_EQ(d.baud, 19200);
  EXPECT_EQ(d.parity, 'E');
  EXPECT_EQ(d.unit, 1);
  EXPECT_EQ(ok("modbus-rtu:///dev/ttyS1?baud=4000000").baud, 4000000);
}

TEST(TransportUri, SocketCanAndSocketcand) {
  const Transport c = ok("socketcan://can0?node=5");
  EXPECT_EQ(c.kind, TransportKind::SocketCan);
  EXPECT_EQ(c.interface_name, "can0");
  EXPECT_EQ(c.node, 5);
  EXPECT_EQ(ok("socketcan://vcan1").node, 1);
  const Transport d = ok("socketcand://127.0.0.1:29536/can0?node=2");
  EXPECT_EQ(d.kind, TransportKind::Socketcand);
  EXPECT_EQ(d.host, "127.0.0.1");
  EXPECT_EQ(d.port, 29536);
  EXPECT_EQ(d.channel, "can0");
  EXPECT_EQ(d.node, 2);
}

TEST(TransportUri, EachMistakeSaysWhatIsWrongAndTheExpectedForm) {
  struct Case {
    const char* uri;
    std::vector<const char*> says;
  };
  const std::vector<Case> cases = {
      {"localhost:502", {"not a URI", "modbus-tcp://HOST:PORT", "socketcand://HOST:PORT/CHANNEL"}},
      {"modbus-udp://x:1", {"unknown scheme 'modbus-udp'", "modbus-rtu:///dev/DEVICE"}},
      {"modbus-tcp://host", {"missing ':PORT'", "modbus-tcp://HOST:PORT[?unit=N]"}},
      {"modbus-tcp://host:0", {"bad port '0'", "1..65535"}},
      {"modbus-tcp://host:70000", {"bad port '70000'"}},
      {"modbus-tcp://:502", {"missing host"}},
      {"modbus-tcp://ho st:502", {"bad host name"}},
      {"modbus-tcp://host:502?unit=300", {"bad unit '300'", "0..255"}},
      {"modbus-tcp://host:502?slave=1", {"unknown query parameter 'slave'", "expected unit"}},
      {"modbus-tcp://host:502?unit=1&unit=2", {"'unit' given twice"}},
      {"modbus-rtu://dev/ttyUSB0", {"absolute device path", "modbus-rtu:///dev/DEVICE"}},
      {"modbus-rtu:///dev/ttyUSB0?baud=12345", {"bad baud '12345'", "standard rate"}},
      {"modbus-rtu:///dev/ttyUSB0?baud=8000000", {"bad baud"}},
      {"modbus-rtu:///dev/ttyUSB0?parity=X", {"bad parity 'X'", "N, E or O"}},
      {"modbus-rtu:///dev/ttyUSB0?unit=0", {"bad unit '0'", "1..247"}},
      {"modbus-rtu:///dev/ttyUSB0?baud", {"expected KEY=VALUE"}},
      {"socketcan://", {"bad interface name ''", "socketcan://IFACE[?node=N]"}},
      {"socketcan://a-very-long-interface-name", {"bad interface name"}},
      {"socketcan://can0?node=200", {"bad node '200'", "1..127"}},
      {"socketcand://127.0.0.1:29536", {"missing '/CHANNEL'", "socketcand://HOST:PORT/CHANNEL"}},
      {"socketcand://127.0.0.1/can0", {"missing ':PORT'"}},
      {"socketcand://[::1:29536/can0", {"unterminated '['"}},
  };
  for (const auto& c : cases) {
    const std::string e = error(c.uri);
    for (const char* word : c.says) EXPECT_NE(e.find(word), std::string::npos) << c.uri << " -> " << e;
  }
}

// The listen addresses of `hybridctl sim serve`: the same HOST:PORT parser, for a local
// IPv4 address where port 0 means any free port.
TEST(ListenAddress, AcceptsHostPortWithOrWithoutAScheme) {
  for (const char* text : {"127.0.0.1:1502", "tcp://127.0.0.1:1502", "modbus-tcp://127.0.0.1:1502?unit=3",
                                  "socketcand://127.0.0.1:1502/can0", "localhost:1502"}) {
    const HostPortResult r = parse_listen_address(text);
    ASSERT_TRUE(r.host_port.has_value()) << text << ": " << r.error;
    EXPECT_EQ(r.host_port->host, "127.0.0.1") << text;
    EXPECT_EQ(r.host_port->port, 1502) << text;
  }
  const HostPortResult any = parse_listen_address("0.0.0.0:0");
  ASSERT_TRUE(any.host_port.has_value()) << any.error;
  EXPECT_EQ(any.host_port->port, 0);
  EXPECT_FALSE(is_loopback_ipv4("0.0.0.0"));
  EXPECT_TRUE(is_loopback_ipv4("127.1.2.3"));
}

TEST(ListenAddress, RefusesWhatCannotBeBound) {
  const struct {
    const char* text;
    const char* says;
  } cases[] = {
      {"tcp://127.0.0.1", "expected [tcp://]HOST:PORT with an IPv4 HOST"},
      {":1502", "expected [tcp://]HOST:PORT"},
      {"127.0.0.1:", "expected [tcp://]HOST:PORT"},
      {"controller.local:1502", "'controller.local' is not an IPv4 address"},
      {"127.0.0.1:70000", "port '70000' is not 0..65535"},
      {"127.0.0.1:000001", "port '000001' is not 0..65535"},
      {"127.0.0.1:-1", "port '-1' is not 0..65535"},
  };
  for (const auto& c : cases) {
    const HostPortResult r = parse_listen_address(c.text);
    EXPECT_FALSE(r.host_port.has_value()) << c.text;
    EXPECT_NE(r.error.find(c.says), std::string::npos) << c.text << " -> " << r.error;
  }
}

TEST(HostPort, ConnectTakesNamesAndIpv6ButNotPortZero) {
  const HostPortResult v6 = parse_host_port("[::1]:502", HostPortUse::Connect, "modbus-tcp://HOST:PORT");
  ASSERT_TRUE(v6.host_port.has_value()) << v6.error;
  EXPECT_EQ(v6.host_port->host, "::1");
  EXPECT_TRUE(parse_host_port("controller.local:502", HostPortUse::Connect, "F").host_port.has_value());
  EXPECT_NE(parse_host_port("host:0", HostPortUse::Connect, "F").error.find("bad port '0', expected 1..65535 in F"),
            std::string::npos);
}

}  // namespace
