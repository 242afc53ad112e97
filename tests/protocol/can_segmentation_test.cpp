// Chunk messages segmented over CAN: frame counts and layouts for short and long messages,
// flow control honoured (block size, separation time, wait, overflow/abort, timeouts), and
// a reassembler that detects lost, repeated and reordered frames and survives garbage.

#include "protocol/can_transfer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <string>
#include <vector>

namespace {

using namespace hybridctl::protocol;
using namespace hybridctl::protocol::can;
using namespace std::chrono_literals;

constexpr std::uint8_t kNode = 5;

std::vector<std::uint8_t> message_of(std::size_t n) {
  std::vector<std::uint8_t> m(n);
  for (std::size_t i = 0; i < n; ++i) m[i] = static_cast<std::uint8_t>(i * 7 + 3);
  return m;
}

/// A loopback between one segmenter and one reassembler with a fake clock advancing 100 us
/// per step. `filter` may drop, repeat or reorder data frames: it gets the frame number
/// (0 = first frame) and returns the frames to deliver.
struct Link {
  CanSegmenter tx{kNode};
  CanReassembler rx;
  Micros now{0};
  std::vector<CanFrame> data_frames;   // as sent
  std::vector<CanFrame> flow_frames;   // as sent by the receiver
  std::vector<std::vector<std::uint8_t>> messages;
  std::vector<TransferError> rx_errors;
  int duplicates = 0;

  explicit Link(ReassemblerSettings settings = {}) : rx(kNode, settings) {}

  void deliver(const CanFrame& f) {
    ReceiveResult r = rx.on_frame(f, now);
    if (r.message) messages.push_back(*r.message);
    if (r.error) rx_errors.push_back(*r.error);
    if (r.duplicate) ++duplicates;
    if (r.flow_control) {
      flow_frames.push_back(*r.flow_control);
      tx.on_flow_control(*r.flow_control, now);
    }
  }

  template <class Filter>
  void run(const std::vector<std::uint8_t>& message, std::uint8_t transfer_id, Filter filter) {
    ASSERT_FALSE(tx.begin(message, transfer_id, now));
    for (int step = 0; step < 100000; ++step) {
      now += 100us;
      if (auto f = tx.poll(now)) {
        data_frames.push_back(*f);
        for (const CanFrame& g : filter(data_frames.size() - 1, *f)) deliver(g);
      }
      ReceiveResult r = rx.poll(now);
      if (r.error) rx_errors.push_back(*r.error);
      if (tx.state() == CanSegmenter::State::Done || tx.state() == CanSegmenter::State::Failed) {
        if (!rx.receiving()) break;
      }
    }
  }
  void run(const std::vector<std::uint8_t>& message, std::uint8_t transfer_id = 9) {
    run(message, transfer_id, [](std::size_t, const CanFrame& f) { return std::vector<CanFrame>{f}; });
  }
};

TEST(CanSegmentation, OneByteTravelsInOneFirstFrameWithoutFlowControl) {
  Link link;
  link.run({0xAB}, 0x42);
  ASSERT_EQ(link.data_frames.size(), 1u);
  const CanFrame expected = make_frame(0x205, std::vector<std::uint8_t>{0x10, 0x01, 0x42, 0xAB});
  EXPECT_EQ(link.data_frames[0], expected);
  EXPECT_TRUE(link.flow_frames.empty());
  ASSERT_EQ(link.messages.size(), 1u);
  EXPECT_EQ(link.messages[0], std::vector<std::uint8_t>{0xAB});
  EXPECT_EQ(link.tx.state(), CanSegmenter::State::Done);
}

TEST(CanSegmentation, FrameCountsFollowFiveBytesInTheFirstFrameAndSevenInEachNext) {
  for (const auto& [length, frames] : std::vector<std::pair<std::size_t, std::size_t>>{
           {1, 1}, {5, 1}, {6, 2}, {7, 2}, {8, 2}, {12, 2}, {13, 3}, {200, 29}, {4095, 586}}) {
    Link link;
    const auto m = message_of(length);
    link.run(m);
    EXPECT_EQ(link.data_frames.size(), frames) << length << " bytes";
    ASSERT_EQ(link.messages.size(), 1u) << length << " bytes";
    EXPECT_EQ(link.messages[0], m);
    EXPECT_TRUE(link.rx_errors.empty()) << link.rx_errors.front().message;
  }
}

TEST(CanSegmentation, SevenAndEightByteMessagesSplitFivePlusTheRest) {
  Link seven;
  seven.run(message_of(7), 1);
  ASSERT_EQ(seven.data_frames.size(), 2u);
  EXPECT_EQ(seven.data_frames[0].len, 8);
  EXPECT_EQ(seven.data_frames[0].data[0], 0x10);
  EXPECT_EQ(seven.data_frames[0].data[1], 7);
  EXPECT_EQ(seven.data_frames[1].len, 3);   // index byte + 2
  EXPECT_EQ(seven.data_frames[1].data[0], 0x21);
  Link eight;
  eight.run(message_of(8), 1);
  ASSERT_EQ(eight.data_frames.size(), 2u);
  EXPECT_EQ(eight.data_frames[1].len, 4);
  EXPECT_EQ(eight.flow_frames.size(), 1u) << "one flow control after the first frame";
}

TEST(CanSegmentation, LongMessageLengthUsesTwelveBitsAndIndicesRollOver) {
  Link link;
  link.run(message_of(200), 0x77);
  const CanFrame& ff = link.data_frames[0];
  EXPECT_EQ(ff.data[0], 0x10);
  EXPECT_EQ(ff.data[1], 200);
  EXPECT_EQ(ff.data[2], 0x77);
  for (std::size_t i = 1; i < link.data_frames.size(); ++i)
    EXPECT_EQ(link.data_frames[i].data[0], 0x20 | (i & 0x0F)) << "consecutive frame " << i;
  Link big;
  big.run(message_of(4095), 1);
  EXPECT_EQ(big.data_frames[0].data[0], 0x1F);
  EXPECT_EQ(big.data_frames[0].data[1], 0xFF);
}

TEST(CanSegmentation, BlockSizeIsHonoured) {
  ReassemblerSettings settings;
  settings.block_size = 4;
  Link link(settings);
  link.run(message_of(200), 3);  // 28 consecutive frames
  // One flow control after the first frame, then after every 4 consecutive frames except
  // when the message is complete: 1 + floor(27 / 4) = 7.
  EXPECT_EQ(link.flow_frames.size(), 7u);
  ASSERT_EQ(link.messages.size(), 1u);

  // Without the receiver's answer, the segmenter stops after the block.
  CanSegmenter tx(kNode);
  ASSERT_FALSE(tx.begin(message_of(200), 3, 0us));
  ASSERT_TRUE(tx.poll(1us));  // first frame
  EXPECT_FALSE(tx.poll(2us)) << "waits for flow control";
  tx.on_flow_control(encode_flow_control({FlowStatus::ContinueToSend, 4, 0, 3}, kNode), 3us);
  int sent = 0;
  for (int i = 0; i < 20; ++i)
    if (tx.poll(Micros{10 + i})) ++sent;
  EXPECT_EQ(sent, 4);
  EXPECT_EQ(tx.state(), CanSegmenter::State::AwaitingFlowControl);
}

TEST(CanSegmentation, SeparationTimeIsHonoured) {
  CanSegmenter tx(kNode);
  ASSERT_FALSE(tx.begin(message_of(50), 1, 0us));
  ASSERT_TRUE(tx.poll(0us));
  tx.on_flow_control(encode_flow_control({FlowStatus::ContinueToSend, 0, 5, 1}, kNode), 1000us);  // 5 ms
  ASSERT_TRUE(tx.poll(1000us)) << "the first consecutive frame may go at once";
  EXPECT_FALSE(tx.poll(5999us));
  EXPECT_EQ(tx.next_send_time(), 6000us);
  EXPECT_TRUE(tx.poll(6000us));
  // Sub-millisecond STmin codes.
  EXPECT_EQ(st_min_duration(0xF1), 100us);
  EXPECT_EQ(st_min_duration(0xF9), 900us);
  EXPECT_EQ(st_min_duration(0x7F), 127ms);
  EXPECT_EQ(st_min_duration(0x80), 127ms) << "reserved values mean the longest time";
}

TEST(CanSegmentation, WaitFramesDelayAndTooManyFail) {
  SegmenterSettings s;
  s.max_wait_frames = 3;
  CanSegmenter tx(kNode, s);
  ASSERT_FALSE(tx.begin(message_of(30), 8, 0us));
  ASSERT_TRUE(tx.poll(0us));
  const CanFrame wait = encode_flow_control({FlowStatus::Wait, 0, 0, 8}, kNode);
  for (int i = 1; i <= 3; ++i) {
    EXPECT_FALSE(tx.on_flow_control(wait, Micros{i * 900'000}));
    EXPECT_FALSE(tx.poll(Micros{i * 900'000 + 1}));
    EXPECT_EQ(tx.state(), CanSegmenter::State::AwaitingFlowControl) << "each wait restarts the timeout";
  }
  tx.on_flow_control(wait, 3'000'000us);
  EXPECT_EQ(tx.state(), CanSegmenter::State::Failed);
  EXPECT_EQ(tx.error()->kind, TransferErrorKind::TooManyWaits);
}

TEST(CanSegmentation, MissingFlowControlTimesOut) {
  CanSegmenter tx(kNode);
  ASSERT_FALSE(tx.begin(message_of(30), 8, 0us));
  ASSERT_TRUE(tx.poll(0us));
  EXPECT_FALSE(tx.poll(1'000'000us));
  EXPECT_EQ(tx.state(), CanSegmenter::State::AwaitingFlowControl);
  EXPECT_FALSE(tx.poll(1'000'001us));
  EXPECT_EQ(tx.state(), CanSegmenter::State::Failed);
  EXPECT_EQ(tx.error()->kind, TransferErrorKind::Timeout);
  // A failed transfer frees the segmenter for the next one.
  EXPECT_FALSE(tx.begin(message_of(3), 9, 2'000'000us));
}

TEST(CanSegmentation, OverlongMessageIsRefusedWithOverflow) {
  ReassemblerSettings settings;
  settings.max_message = 100;
  Link link(settings);
  link.run(message_of(200), 4);
  ASSERT_EQ(link.flow_frames.size(), 1u);
  EXPECT_EQ(link.flow_frames[0].data[0], 0x32);
  EXPECT_TRUE(link.messages.empty());
  ASSERT_FALSE(link.rx_errors.empty());
  EXPECT_EQ(link.rx_errors[0].kind, TransferErrorKind::TooLong);
  EXPECT_EQ(link.tx.state(), CanSegmenter::State::Failed);
  EXPECT_EQ(link.tx.error()->kind, TransferErrorKind::Refused);
  EXPECT_EQ(link.data_frames.size(), 1u) << "nothing sent after the refusal";
}

TEST(CanSegmentation, SegmenterIgnoresStaleAndGarbageFlowControl) {
  CanSegmenter tx(kNode);
  ASSERT_FALSE(tx.begin(message_of(30), 8, 0us));
  ASSERT_TRUE(tx.poll(0us));
  auto stale = tx.on_flow_control(encode_flow_control({FlowStatus::ContinueToSend, 0, 0, 7}, kNode), 1us);
  ASSERT_TRUE(stale);
  EXPECT_EQ(stale->kind, TransferErrorKind::StaleFlowControl);
  EXPECT_EQ(tx.on_flow_control(encode_flow_control({FlowStatus::OverflowAbort, 0, 0, 8}, 6), 1us)->kind,
            TransferErrorKind::WrongId);
  EXPECT_EQ(tx.on_flow_control(make_frame(flow_control_id(kNode), std::vector<std::uint8_t>{0x30, 0}), 1us)->kind,
            TransferErrorKind::Malformed);
  EXPECT_EQ(tx.on_flow_control(make_frame(flow_control_id(kNode), std::vector<std::uint8_t>{0x35, 0, 0, 8}), 1us)->kind,
            TransferErrorKind::Malformed);
  EXPECT_EQ(tx.state(), CanSegmenter::State::AwaitingFlowControl);
  EXPECT_FALSE(tx.on_flow_control(encode_flow_control({FlowStatus::ContinueToSend, 0, 0, 8}, kNode), 2us));
  EXPECT_EQ(tx.state(), CanSegmenter::State::Sending);
}

TEST(CanSegmentation, SegmenterRefusesASecondMessageWhileBusyAndBadLengths) {
  CanSegmenter tx(kNode);
  EXPECT_EQ(tx.begin({}, 1, 0us)->kind, TransferErrorKind::TooLong);
  EXPECT_EQ(tx.begin(message_of(4096), 1, 0us)->kind, TransferErrorKind::TooLong);
  ASSERT_FALSE(tx.begin(message_of(30), 1, 0us));
  auto busy = tx.begin(message_of(3), 2, 0us);
  ASSERT_TRUE(busy);
  EXPECT_EQ(busy->kind, TransferErrorKind::Busy);
  EXPECT_EQ(tx.transfer_id(), 1);
}

// ------------------------------------------------------------ reassembly under faults

std::vector<CanFrame> keep(const CanFrame& f) { return {f}; }

TEST(CanReassembly, ALostConsecutiveFrameIsDetectedAndTheSenderAborted) {
  Link link;
  link.run(message_of(200), 2, [](std::size_t n, const CanFrame& f) {
    return n == 3 ? std::vector<CanFrame>{} : keep(f);
  });
  EXPECT_TRUE(link.messages.empty());
  ASSERT_FALSE(link.rx_errors.empty());
  EXPECT_EQ(link.rx_errors[0].kind, TransferErrorKind::SequenceError);
  EXPECT_NE(link.rx_errors[0].message.find("consecutive frame 4 where 3 was expected"), std::string::npos)
      << link.rx_errors[0].message;
  EXPECT_EQ(link.flow_frames.back().data[0], 0x32) << "overflow/abort tells the sender";
  EXPECT_EQ(link.tx.state(), CanSegmenter::State::Failed);
  EXPECT_EQ(link.tx.error()->kind, TransferErrorKind::Refused);
  EXPECT_EQ(link.rx.sequence_errors(), 1u);
}

TEST(CanReassembly, AnExactRepeatOfTheLastFrameIsIgnoredAndTheMessageStillArrives) {
  Link link;
  const auto m = message_of(200);
  link.run(m, 2, [](std::size_t n, const CanFrame& f) {
    return n == 5 || n == 0 ? std::vector<CanFrame>{f, f} : keep(f);
  });
  ASSERT_EQ(link.messages.size(), 1u);
  EXPECT_EQ(link.messages[0], m);
  EXPECT_EQ(link.duplicates, 2);
  EXPECT_EQ(link.rx.duplicates_ignored(), 2u);
  EXPECT_TRUE(link.rx_errors.empty());
}

TEST(CanReassembly, ARepeatedIndexWithOtherDataIsASequenceError) {
  CanReassembler rx(kNode);
  const auto m = message_of(30);
  CanSegmenter tx(kNode);
  ASSERT_FALSE(tx.begin(m, 1, 0us));
  auto fc = rx.on_frame(*tx.poll(0us), 0us).flow_control;
  tx.on_flow_control(*fc, 0us);
  CanFrame cf1 = *tx.poll(1us);
  EXPECT_FALSE(rx.on_frame(cf1, 1us).error);
  cf1.data[3] ^= 0xFF;
  auto r = rx.on_frame(cf1, 2us);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->kind, TransferErrorKind::SequenceError);
  EXPECT_FALSE(r.duplicate);
}

TEST(CanReassembly, ReorderedFramesAreDetected) {
  Link link;
  CanFrame held;
  link.run(message_of(200), 2, [&held](std::size_t n, const CanFrame& f) {
    if (n == 4) {
      held = f;
      return std::vector<CanFrame>{};
    }
    if (n == 5) return std::vector<CanFrame>{f, held};
    return keep(f);
  });
  EXPECT_TRUE(link.messages.empty());
  ASSERT_FALSE(link.rx_errors.empty());
  EXPECT_EQ(link.rx_errors[0].kind, TransferErrorKind::SequenceError);
}

TEST(CanReassembly, LosingAWholeIndexCycleEndsInATimeoutNeverAWrongMessage) {
  ReassemblerSettings settings;
  settings.block_size = 0;  // no flow control after the first: the sender sends everything
  Link link(settings);
  // 194 bytes = 5 + 27 full consecutive frames, so no short last frame gives the loss away.
  link.run(message_of(194), 2, [](std::size_t n, const CanFrame& f) {
    return n >= 3 && n < 19 ? std::vector<CanFrame>{} : keep(f);  // 16 frames: the index repeats
  });
  EXPECT_TRUE(link.messages.empty());
  ASSERT_FALSE(link.rx_errors.empty());
  EXPECT_EQ(link.rx_errors.back().kind, TransferErrorKind::Timeout);
  EXPECT_EQ(link.rx.timeouts(), 1u);
}

TEST(CanReassembly, LosingAWholeIndexCycleBeforeAShortLastFrameIsMalformed) {
  ReassemblerSettings settings;
  settings.block_size = 0;
  Link link(settings);
  link.run(message_of(200), 2, [](std::size_t n, const CanFrame& f) {
    return n >= 3 && n < 19 ? std::vector<CanFrame>{} : keep(f);
  });
  EXPECT_TRUE(link.messages.empty());
  ASSERT_FALSE(link.rx_errors.empty());
  EXPECT_EQ(link.rx_errors.back().kind, TransferErrorKind::Malformed) << link.rx_errors.back().message;
}

TEST(CanReassembly, ASilentSenderTimesOut) {
  CanReassembler rx(kNode);
  auto r = rx.on_frame(make_frame(data_id(kNode), std::vector<std::uint8_t>{0x10, 20, 1, 1, 2, 3, 4, 5}), 0us);
  ASSERT_TRUE(r.flow_control);
  EXPECT_FALSE(rx.poll(1'000'000us).error);
  auto late = rx.poll(1'000'001us);
  ASSERT_TRUE(late.error);
  EXPECT_EQ(late.error->kind, TransferErrorKind::Timeout);
  EXPECT_FALSE(rx.receiving());
}

TEST(CanReassembly, ANewFirstFrameReplacesAnUnfinishedTransfer) {
  CanReassembler rx(kNode);
  rx.on_frame(make_frame(data_id(kNode), std::vector<std::uint8_t>{0x10, 20, 1, 1, 2, 3, 4, 5}), 0us);
  auto r = rx.on_frame(make_frame(data_id(kNode), std::vector<std::uint8_t>{0x10, 3, 2, 7, 8, 9}), 1us);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->kind, TransferErrorKind::Interrupted);
  ASSERT_TRUE(r.message);
  EXPECT_EQ(*r.message, (std::vector<std::uint8_t>{7, 8, 9}));
  EXPECT_EQ(r.transfer_id, 2);
}

TEST(CanReassembly, GarbageIsReportedAndNeverCrashes) {
  CanReassembler rx(kNode);
  auto error_of = [&](CanFrame f) {
    auto r = rx.on_frame(f, 0us);
    EXPECT_FALSE(r.message);
    return r.error ? r.error->kind : TransferErrorKind::Busy;
  };
  EXPECT_EQ(error_of(make_frame(data_id(kNode + 1), std::vector<std::uint8_t>{0x10, 1, 0, 0})), TransferErrorKind::WrongId);
  EXPECT_EQ(error_of(make_frame(data_id(kNode), {})), TransferErrorKind::Malformed);
  CanFrame too_long = make_frame(data_id(kNode), std::vector<std::uint8_t>{0x21, 1, 2});
  too_long.len = 15;
  EXPECT_EQ(error_of(too_long), TransferErrorKind::Malformed);
  EXPECT_EQ(error_of(make_frame(data_id(kNode), std::vector<std::uint8_t>{0x21, 1, 2})), TransferErrorKind::Unexpected);
  EXPECT_EQ(error_of(make_frame(data_id(kNode), std::vector<std::uint8_t>{0x30, 0, 0, 1})), TransferErrorKind::Malformed);
  EXPECT_EQ(error_of(make_frame(data_id(kNode), std::vector<std::uint8_t>{0x10, 0, 1})), TransferErrorKind::Malformed);
  EXPECT_EQ(error_of(make_frame(data_id(kNode), std::vector<std::uint8_t>{0x10, 9, 1, 1})), TransferErrorKind::Malformed)
      << "a first frame must carry min(5, length) bytes";
  EXPECT_EQ(error_of(make_frame(data_id(kNode), std::vector<std::uint8_t>{0x10})), TransferErrorKind::Malformed);
  EXPECT_EQ(error_of(make_frame(data_id(kNode), std::vector<std::uint8_t>{0xF0, 1})), TransferErrorKind::Malformed);
  EXPECT_EQ(rx.frames_ignored(), 9u);
  // A short consecutive frame that is not the last drops the transfer.
  rx.on_frame(make_frame(data_id(kNode), std::vector<std::uint8_t>{0x10, 20, 1, 1, 2, 3, 4, 5}), 0us);
  auto r = rx.on_frame(make_frame(data_id(kNode), std::vector<std::uint8_t>{0x21, 1, 2}), 0us);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->kind, TransferErrorKind::Malformed);
  EXPECT_FALSE(rx.receiving());
}

TEST(CanReassembly, FirstFramePaddingAndLastFramePaddingAreAccepted) {
  CanReassembler rx(kNode);
  // 3-byte message in a padded 8-byte first frame.
  auto r = rx.on_frame(make_frame(data_id(kNode), std::vector<std::uint8_t>{0x10, 3, 1, 7, 8, 9, 0xCC, 0xCC}), 0us);
  ASSERT_TRUE(r.message);
  EXPECT_EQ(*r.message, (std::vector<std::uint8_t>{7, 8, 9}));
  // 6-byte message: the consecutive frame padded to 8 bytes.
  rx.on_frame(make_frame(data_id(kNode), std::vector<std::uint8_t>{0x10, 6, 2, 1, 2, 3, 4, 5}), 0us);
  r = rx.on_frame(make_frame(data_id(kNode), std::vector<std::uint8_t>{0x21, 6, 0xCC, 0xCC, 0xCC, 0xCC, 0xCC, 0xCC}), 0us);
  ASSERT_TRUE(r.message);
  EXPECT_EQ(*r.message, (std::vector<std::uint8_t>{1, 2, 3, 4, 5, 6}));
}

TEST(CanChunks, AChunkTravelsSegmentedAndDecodesToItself) {
  Chunk c;
  c.seq = 300;  // transfer id 300 & 0xFF = 44
  c.identity_tag = 0xCAFEF00D;
  c.first_line = 12345;
  std::string payload;
  for (int i = 0; i < 40; ++i) payload += "G1 X" + std::to_string(i) + " Y-" + std::to_string(i) + " F900\n";
  c.line_count = 40;
  c.payload = payload;
  auto message = encode_chunk_message(c);
  ASSERT_TRUE(message) << message.error().message;
  Link link;
  link.run(*message, chunk_transfer_id(c.seq));
  ASSERT_EQ(link.messages.size(), 1u);
  EXPECT_EQ(link.data_frames[0].data[2], 44);
  auto decoded = decode_chunk_message(link.messages[0]);
  ASSERT_TRUE(decoded) << decoded.error().message;
  EXPECT_EQ(*decoded, c);
  // The CAN limit: 4075 payload bytes.
  Chunk big = c;
  big.payload = std::string(4074, 'X') + "\n";
  big.line_count = 1;
  EXPECT_TRUE(encode_chunk_message(big));
  big.payload = std::string(4075, 'X') + "\n";
  EXPECT_EQ(encode_chunk_message(big).error().code, ResultCode::TooLong);
}

}  // namespace
