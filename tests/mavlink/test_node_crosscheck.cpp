// SPDX-License-Identifier: MIT
// The codec against an independent implementation, byte for byte and both ways: node-mavlink (npm, with
// mavlink-mappings generated from the same XML) encodes the same seeded random messages, and decodes the C++
// frames through its stream splitter; the C++ parser decodes node-mavlink's frames.
// Exits 77 (ctest SKIP_RETURN_CODE) with a message when node or the npm packages are absent
// (tools/install_deps.sh installs them: `npm ci` in tests/mavlink/node).
#include "mavlink_test_helpers.hpp"

#include <wingman/mavlink/parser.hpp>

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>

namespace fs = std::filesystem;
using namespace wingman::mavlink;
using namespace wingman::mavlink::test;

namespace {

fs::path source_dir() {
  const char* s = std::getenv("WINGMAN_SOURCE_DIR");
  return s ? fs::path(s) : fs::current_path();
}
fs::path node_project() { return source_dir() / "tests" / "mavlink" / "node"; }

/// The node executable on PATH, or "".
std::string find_node() {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const fs::path p = fs::path(dir) / "node";
    if (::access(p.c_str(), X_OK) == 0) return p.string();
  }
  return "";
}

/// Zeroes the fields after extensions() (a MAVLink 1 frame has none).
class ZeroExtensions {
 public:
  template <class T>
  void field(std::string_view, T& v) {
    if (ext_) v = T{};
  }
  template <class T, size_t N>
  void field(std::string_view, std::array<T, N>& a) {
    if (ext_) a = {};
  }
  void extensions() { ext_ = true; }

 private:
  bool ext_ = false;
};

struct Case {
  std::string name;
  Version version = Version::kV2;
  Sender sender;
  std::vector<uint8_t> frame;                  ///< the C++ codec's frame
  std::array<uint8_t, kMaxPayload> payload{};  ///< the message's fields
  bool bytes_comparable = true;                ///< false: v1 of a message with extensions (node sends them)
  std::function<std::array<uint8_t, kMaxPayload>(const std::map<std::string, std::string>&, std::string*)> read_text;
  std::function<bool(const Frame&, std::array<uint8_t, kMaxPayload>*)> decode_frame;
  std::string line;  ///< the input line for crosscheck.js
};

struct Answer {
  std::string node_hex;
  std::map<std::string, std::string> fields;  ///< as node-mavlink decoded the C++ frame (incl. seq, sysid, compid)
  std::string error;
};

template <class Msg>
void add_cases(std::vector<Case>& cases, std::mt19937& rng) {
  const MessageInfo& info = *find_message(Msg::kId);
  for (const Version version : {Version::kV2, Version::kV1}) {
    if (version == Version::kV1 && Msg::kId > 255) continue;
    for (const double zero_p : {0.0, 0.3, 0.7}) {
      for (int i = 0; i < 6; ++i) {
        Msg msg;
        Randomizer random(rng, zero_p);
        msg.visit(random);
        if (version == Version::kV1) {
          ZeroExtensions zero;
          msg.visit(zero);
        }
        const auto payload = payload_bytes(msg);
        // node-mavlink sends 0 bytes for an all-zero payload where MAVLink keeps one: not compared here (the
        // C++ parser's reading of an empty payload is a unit test).
        if (std::all_of(payload.begin(), payload.end(), [](uint8_t b) { return b == 0; })) continue;
        Case c;
        c.name = Msg::kName;
        c.version = version;
        c.sender = Sender{static_cast<uint8_t>(rng() % 255 + 1), static_cast<uint8_t>(rng() % 256),
                          static_cast<uint8_t>(rng() % 256)};
        c.frame = encode(msg, c.sender, version);
        c.payload = payload;
        c.bytes_comparable = version == Version::kV2 || info.base_length == info.max_length;
        c.read_text = [](const std::map<std::string, std::string>& values, std::string* missing) {
          Msg m;
          TextReader reader(values);
          m.visit(reader);
          *missing = reader.missing();
          return payload_bytes(m);
        };
        c.decode_frame = [](const Frame& f, std::array<uint8_t, kMaxPayload>* out) {
          Msg m;
          if (!decode(f, m)) return false;
          *out = payload_bytes(m);
          return true;
        };
        TextWriter text;
        msg.visit(text);
        std::ostringstream line;
        line << c.name << (version == Version::kV1 ? " v1 " : " v2 ") << int(c.sender.sysid) << ' '
             << int(c.sender.compid) << ' ' << int(c.sender.seq) << ' ' << to_hex(c.frame) << text.str();
        c.line = line.str();
        cases.push_back(std::move(c));
      }
    }
  }
}

struct Run {
  std::vector<Case> cases;
  std::vector<Answer> answers;
  std::string error;
};

/// Builds the cases (fixed seed), runs crosscheck.js once over all of them and reads its answers.
const Run& run() {
  static const Run r = [] {
    Run out;
    std::mt19937 rng(20261205);
    for_each_message_type([&](auto msg) { add_cases<decltype(msg)>(out.cases, rng); });
    const fs::path dir = fs::temp_directory_path() / ("wingman_mavlink_node_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    {
      std::ofstream in(dir / "cases.txt");
      for (const auto& c : out.cases) in << c.line << '\n';
    }
    const std::string cmd = "'" + find_node() + "' '" + (node_project() / "crosscheck.js").string() + "' '" +
                            (dir / "cases.txt").string() + "' > '" + (dir / "answers.txt").string() + "' 2> '" +
                            (dir / "stderr.txt").string() + "'";
    const int rc = std::system(cmd.c_str());
    std::ifstream answers(dir / "answers.txt");
    std::string line;
    while (std::getline(answers, line)) {
      std::istringstream words(line);
      std::string index, hex, word;
      words >> index >> hex;
      Answer a;
      if (hex == "ERROR") {
        std::getline(words, a.error);
      } else {
        a.node_hex = hex;
        while (words >> word) {
          const auto eq = word.find('=');
          a.fields[word.substr(0, eq)] = word.substr(eq + 1);
        }
      }
      out.answers.push_back(std::move(a));
    }
    if (rc != 0 || out.answers.size() != out.cases.size()) {
      std::ifstream err(dir / "stderr.txt");
      std::stringstream text;
      text << err.rdbuf();
      out.error = "crosscheck.js exit " + std::to_string(rc) + ", " + std::to_string(out.answers.size()) +
                  " answers for " + std::to_string(out.cases.size()) + " cases: " + text.str();
    }
    fs::remove_all(dir);
    return out;
  }();
  return r;
}

void check_message(const std::string& name) {
  const Run& r = run();
  ASSERT_EQ(r.error, "");
  int checked = 0;
  for (size_t i = 0; i < r.cases.size(); ++i) {
    const Case& c = r.cases[i];
    if (c.name != name) continue;
    ++checked;
    const Answer& a = r.answers[i];
    SCOPED_TRACE("case " + std::to_string(i) + ": " + c.line);
    ASSERT_EQ(a.error, "");
    // 1. Same bytes from both encoders.
    if (c.bytes_comparable) {
      EXPECT_EQ(a.node_hex, to_hex(c.frame)) << "node-mavlink's frame differs";
    }
    // 2. node-mavlink reads the C++ frame back to the same fields.
    std::string missing;
    EXPECT_EQ(c.read_text(a.fields, &missing), c.payload) << "node-mavlink decoded other values";
    EXPECT_EQ(missing, "") << "fields node-mavlink did not decode";
    EXPECT_EQ(a.fields.at("seq"), std::to_string(c.sender.seq));
    EXPECT_EQ(a.fields.at("sysid"), std::to_string(c.sender.sysid));
    EXPECT_EQ(a.fields.at("compid"), std::to_string(c.sender.compid));
    // 3. The C++ parser reads node-mavlink's frame back to the same fields.
    Parser parser;
    const auto bytes = from_hex(a.node_hex);
    int frames = 0;
    parser.feed(bytes.data(), bytes.size(), [&](const Frame& f) {
      ++frames;
      std::array<uint8_t, kMaxPayload> decoded{};
      EXPECT_TRUE(c.decode_frame(f, &decoded));
      EXPECT_EQ(decoded, c.payload) << "the C++ codec decoded node-mavlink's frame to other values";
      EXPECT_EQ(f.seq, c.sender.seq);
      EXPECT_EQ(f.sysid, c.sender.sysid);
      EXPECT_EQ(f.compid, c.sender.compid);
      EXPECT_EQ(f.version, c.version);
    });
    EXPECT_EQ(frames, 1) << parser.stats().summary();
  }
  EXPECT_GE(checked, 15) << "too few cases for " << name;
}

}  // namespace

TEST(MavlinkNodeCrosscheck, Heartbeat) { check_message("HEARTBEAT"); }
TEST(MavlinkNodeCrosscheck, SystemTime) { check_message("SYSTEM_TIME"); }
TEST(MavlinkNodeCrosscheck, AttitudeQuaternion) { check_message("ATTITUDE_QUATERNION"); }
TEST(MavlinkNodeCrosscheck, LocalPositionNed) { check_message("LOCAL_POSITION_NED"); }
TEST(MavlinkNodeCrosscheck, CommandLong) { check_message("COMMAND_LONG"); }
TEST(MavlinkNodeCrosscheck, CommandAck) { check_message("COMMAND_ACK"); }
TEST(MavlinkNodeCrosscheck, SetPositionTargetLocalNed) { check_message("SET_POSITION_TARGET_LOCAL_NED"); }
TEST(MavlinkNodeCrosscheck, PositionTargetLocalNed) { check_message("POSITION_TARGET_LOCAL_NED"); }
TEST(MavlinkNodeCrosscheck, Timesync) { check_message("TIMESYNC"); }
TEST(MavlinkNodeCrosscheck, Odometry) { check_message("ODOMETRY"); }

TEST(MavlinkNodeCrosscheck, EveryHandledMessageIsCovered) {
  std::set<std::string> names;
  for (const auto& c : run().cases) names.insert(c.name);
  EXPECT_EQ(names.size(), known_messages().size());
}

int main(int argc, char** argv) {
  if (find_node().empty()) {
    std::printf("SKIP: node is not installed (tools/install_deps.sh installs nodejs and npm)\n");
    return 77;
  }
  if (!fs::exists(node_project() / "node_modules" / "node-mavlink" / "package.json")) {
    std::printf("SKIP: node-mavlink is not installed in %s (tools/install_deps.sh runs `npm ci` there)\n",
                node_project().c_str());
    return 77;
  }
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
