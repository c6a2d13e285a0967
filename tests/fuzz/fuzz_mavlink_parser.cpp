// SPDX-License-Identifier: MIT
// Fuzz target: the MAVLink stream parser (wingman-mavlink's serial and UDP input). The input is a sequence of
// records (fuzz_support.hpp); selector % 4: 0-2 = bytes fed to the parser, 3 = end of a datagram. Every frame handed
// on must be of a known message and no longer than its fields, must decode, and encoded again must parse back to
// the same fields; the parser must account for every byte fed.
#include "fuzz_support.hpp"

#include <wingman/mavlink/parser.hpp>

#include <cstdio>
#include <cstdlib>

namespace {

using namespace wingman::mavlink;

[[noreturn]] void fail(const char* what, const Frame& f) {
  std::fprintf(stderr, "mavlink parser: %s (msgid %u, length %u)\n", what, f.msgid, f.payload_length);
  std::abort();
}

/// Decodes `f` as its message type, encodes it again as v2 and checks that it parses back to the same payload.
void check_frame(const Frame& f) {
  const MessageInfo* info = find_message(f.msgid);
  if (info == nullptr) fail("a frame of an unknown message was handed on", f);
  if (f.payload_length > info->max_length) fail("payload longer than the message's fields", f);
  for (size_t i = f.payload_length; i < f.payload.size(); ++i)
    if (f.payload[i] != 0) fail("payload not zero past its length", f);
  bool decoded = false;
  for_each_message_type([&](auto msg) {
    if (!decode(f, msg)) return;
    decoded = true;
    const auto bytes = encode(msg, Sender{f.sysid, f.compid, f.seq});
    Parser again;
    int n = 0;
    again.feed(bytes.data(), bytes.size(), [&](const Frame& g) {
      ++n;
      if (g.msgid != f.msgid || g.payload != f.payload) fail("re-encoded frame parses to other fields", f);
    });
    if (n != 1) fail("re-encoded frame not found by a fresh parser", f);
  });
  if (!decoded) fail("no message type decodes a frame the table knows", f);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Parser parser;
  wingman::fuzz::Records records(data, size);
  uint8_t selector = 0;
  const uint8_t* payload = nullptr;
  size_t n = 0;
  int64_t fed = 0;
  while (records.next(&selector, &payload, &n)) {
    if (selector % 4 == 3) {
      parser.end_of_datagram(check_frame);
    } else {
      parser.feed(payload, n, check_frame);
      fed += static_cast<int64_t>(n);
    }
  }
  if (parser.stats().bytes != fed) {
    std::fprintf(stderr, "mavlink parser: counted %lld bytes of %lld\n", static_cast<long long>(parser.stats().bytes),
                 static_cast<long long>(fed));
    std::abort();
  }
  return 0;
}
