// SPDX-License-Identifier: MIT
// Fuzz target: the LCM log container (common::LcmLogReader, the reader of every file:// input and tool verb).
// The input is a log file's bytes. Read strictly, it must give valid events and then end or throw LcmLogError
// naming an offset inside the file; read with skip_corrupt, it must never throw and must account for every byte
// (events plus skipped bytes = the file). No event may claim more bytes than the file holds.
#include <wingman/common/lcm_log_reader.hpp>

#include <cstdint>
#include <cstdio>
#include <cstdlib>

namespace {

void fail(const char* what, long long a, long long b) {
  std::fprintf(stderr, "fuzz_lcm_log: %s (%lld, %lld)\n", what, a, b);
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using wingman::common::LcmLogError;
  using wingman::common::LcmLogReader;
  const auto n = static_cast<long long>(size);
  {
    LcmLogReader strict = LcmLogReader::from_memory(data, size, "fuzz.lcmlog");
    long long previous_end = 0;
    try {
      while (const auto* e = strict.read_next()) {
        const long long end = e->offset + 28 + static_cast<long long>(e->channel.size()) + e->datalen;
        if (e->offset != previous_end)
          fail("strict: an event does not start where the previous ended", e->offset, previous_end);
        if (end > n) fail("strict: an event runs past the end of the file", end, n);
        if (e->channel.empty() || e->datalen < 0) fail("strict: empty channel or negative length", e->datalen, 0);
        previous_end = end;
      }
    } catch (const LcmLogError& err) {
      if (err.offset() < 0 || err.offset() >= n) fail("strict: corrupt offset outside the file", err.offset(), n);
    }
  }
  wingman::common::LcmLogReadOptions skip;
  skip.skip_corrupt = true;
  LcmLogReader lenient = LcmLogReader::from_memory(data, size, "fuzz.lcmlog", skip);
  long long event_bytes = 0;
  for (int i = 0; i < 100000; ++i) {
    const auto* e = lenient.read_next();  // must not throw
    if (!e) break;
    event_bytes += 28 + static_cast<long long>(e->channel.size()) + e->datalen;
  }
  if (size > 0 && event_bytes + lenient.skipped_bytes() != n)
    fail("skip: events and skipped bytes do not add up to the file", event_bytes + lenient.skipped_bytes(), n);
  return 0;
}
