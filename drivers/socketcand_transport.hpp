#pragma once
// A CAN bus on another host, reached over TCP through socketcand's text protocol
// (https://github.com/linux-can/socketcand, raw mode), under the CAN link
// (drivers/can_link.hpp):
//
//   server: < hi >                       on connect
//   client: < open CHANNEL >             server: < ok >
//   client: < rawmode >                  server: < ok >
//   client: < send ID LEN B0 B1 ... >    ID hex, LEN 0..8, bytes unpadded hex
//   server: < frame ID SEC.USEC DATAHEX >   ID %03X (%08X: a 29-bit identifier), data bytes
//                                        run together
//
// The reader takes any byte stream: text outside `< ... >`, over-long elements, unknown
// or malformed elements (a corrupt frame, `< error ... >`) are skipped and counted, never
// trusted; a frame with a 29-bit identifier is not the protocol's and is skipped too.

#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/can_link.hpp"

namespace hybridctl::drivers {

/// Splits a socketcand byte stream into elements.
class SocketcandReader {
 public:
  /// Longer elements are garbage (the longest real one, a frame with a 29-bit identifier
  /// and 8 bytes, has about 50 characters).
  static constexpr std::size_t kMaxElement = 256;

  void feed(std::string_view bytes);
  /// The words of the next complete element (between '<' and '>', split at whitespace;
  /// empty for "< >"), or nullopt until more bytes come.
  std::optional<std::vector<std::string>> next();
  /// Bytes skipped: outside elements, in over-long or unterminated elements.
  std::uint64_t garbage_bytes() const { return garbage_bytes_; }

 private:
  std::string buffer_;
  std::size_t pos_ = 0;
  std::uint64_t garbage_bytes_ = 0;
};

struct SocketcandFrame {
  std::optional<protocol::can::CanFrame> frame;  ///< set for a valid frame element
  bool extended = false;                         ///< a 29-bit identifier (frame set too)
  std::string error;                             ///< otherwise: what is wrong with it
};

/// Reads the words of `< frame ID SEC.USEC DATAHEX >` ("frame", ID, time, data; the data
/// word is absent for a frame without data bytes).
SocketcandFrame parse_socketcand_frame(std::span<const std::string> words);

/// "< send 201 8 10 E 1 0 0 0 1 0 >": the element that puts `frame` on the bus.
std::string format_socketcand_send(const protocol::can::CanFrame& frame);

class SocketcandIo final : public CanFrameIo {
 public:
  SocketcandIo(std::string host, int port, std::string channel);
  ~SocketcandIo() override;
  SocketcandIo(const SocketcandIo&) = delete;
  SocketcandIo& operator=(const SocketcandIo&) = delete;

  std::string describe() const override;
  void open(std::chrono::milliseconds timeout) override;
  void close() override;
  bool is_open() const override { return fd_ >= 0; }
  void send(std::span<const protocol::can::CanFrame> frames) override;
  std::optional<protocol::can::CanFrame> receive(SteadyTime deadline) override;
  /// Elements skipped (malformed, unknown, `< error >`) plus runs of bytes outside elements.
  std::uint64_t garbage() const override { return bad_elements_ + garbage_runs_; }

 private:
  // Reads more bytes into the reader, waiting until `deadline`; false when none came.
  bool fill(SteadyTime deadline);
  std::vector<std::string> expect(SteadyTime deadline, const std::string& after);
  void write_all(std::string_view text);

  std::string host_;
  int port_;
  std::string channel_;
  int fd_ = -1;
  std::chrono::milliseconds timeout_{500};
  SocketcandReader reader_;
  std::uint64_t bad_elements_ = 0;
  std::uint64_t garbage_runs_ = 0;
  std::uint64_t last_garbage_bytes_ = 0;
};

}  // namespace hybridctl::drivers
