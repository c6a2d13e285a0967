// SPDX-License-Identifier: MIT
// The log verbs' command lines: `wingman replay`, `spy`, `make-video` and `loginfo`, each with its options as data
// (--config FILE, --set KEY=VALUE, --print-config: VerbLayers).
#include "wingman/tools/log_cli.hpp"

#include "verb_layers.hpp"
#include "wingman/tools/log_info.hpp"
#include "wingman/tools/make_video.hpp"
#include "wingman/tools/replay.hpp"
#include "wingman/tools/spy.hpp"

#include <wingman/common/config.hpp>

#include <exception>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace wingman::tools {

namespace {

/// `wingman replay`'s options as keys.
struct ReplayVerbOptions {
  ReplayOptions replay;
  bool quiet = false;  ///< no progress on stderr

  template <class V>
  void visit(V& v) {
    v("input.log", replay.input_log, "the LCM log to play");
    v("input.channels", replay.channels, "regular expression of channels to play; \"\" = all but STATUS_*");
    v("input.exclude", replay.exclude, "regular expression of channels not to play (e.g. the stages' own outputs)");
    v("input.max_events", replay.max_events, "play at most this many events; 0 = all");
    v("input.skip_corrupt", replay.skip_corrupt,
      "skip and count corrupt log events; false = stop at the first, naming its byte offset");
    v("bus.lcm_url", replay.lcm_url, "LCM URL to publish on and listen to; \"\" = LCM_DEFAULT_URL");
    v("lockstep.wait_for", replay.stages,
      "process instance names (as in their status) to run in lockstep with; each must run with --lockstep");
    v("lockstep.start_timeout_s", replay.start_timeout_s, "seconds to wait for every lockstep process to report");
    v("lockstep.step_timeout_s", replay.step_timeout_s, "seconds to wait for the pipeline to settle after a message");
    v("playback.speed", replay.speed, "without lockstep: 1 = real time, 0 = as fast as possible");
    v("output.record", replay.record_log, "write every message seen on the bus (but status) to this LCM log");
    v("output.quiet", quiet, "no progress on stderr");
  }
  std::vector<std::string> validate() const { return replay.validate(); }
};

/// `wingman spy`'s options as keys.
struct SpyVerbOptions {
  SpyOptions spy;

  template <class V>
  void visit(V& v) {
    v("bus.lcm_url", spy.lcm_url, "LCM URL to listen on; \"\" = LCM_DEFAULT_URL");
    v("spy.java", spy.java, "Java runtime");
    v("spy.types_jar", spy.types_jar, "jar with the wingman message classes; \"\" = the built one");
    v("spy.dry_run", spy.dry_run, "print the java command instead of running it");
  }
  std::vector<std::string> validate() const {
    if (spy.java.empty()) return {"spy.java: must not be empty"};
    return {};
  }
};

/// `wingman make-video`'s options as keys.
struct MakeVideoVerbOptions {
  MakeVideoOptions video;

  template <class V>
  void visit(V& v) {
    v("output.file", video.output, "the .avi file to write (MJPG)");
    v("video.frames", video.frames, "number of frames, 1..100000");
    v("video.width", video.width, "width, pixels, 16..8192");
    v("video.height", video.height, "height, pixels, 16..8192");
    v("video.fps", video.fps, "frames per second, (0, 1000]");
  }
  std::vector<std::string> validate() const { return video.validate(); }
};

/// `wingman loginfo`'s options as keys.
struct LogInfoVerbOptions {
  std::string log;
  std::string snapshot;
  bool skip_corrupt = false;

  template <class V>
  void visit(V& v) {
    v("input.log", log, "the LCM log to summarize");
    v("input.skip_corrupt", skip_corrupt,
      "skip and count corrupt log events; false = stop at the first, naming its byte offset");
    v("output.snapshot", snapshot, "save the last image_t as this PNG file; \"\" = none");
  }
  std::vector<std::string> validate() const {
    if (log.empty()) return {"input.log: give the log (LOG, or the key)"};
    return {};
  }
};

}  // namespace

struct LogVerbs::State {
  CLI::App* replay = nullptr;
  ReplayVerbOptions replay_flags;  // what the flags say; replay runs with what its layers load
  std::unique_ptr<VerbLayers> replay_layers;
  CLI::App* spy = nullptr;
  SpyVerbOptions spy_flags;
  std::unique_ptr<VerbLayers> spy_layers;
  CLI::App* video = nullptr;
  MakeVideoVerbOptions video_flags;
  std::unique_ptr<VerbLayers> video_layers;
  CLI::App* info = nullptr;
  LogInfoVerbOptions info_flags;
  std::unique_ptr<VerbLayers> info_layers;
};

LogVerbs::LogVerbs(CLI::App& app) : s_(std::make_unique<State>()) {
  ReplayOptions& replay = s_->replay_flags.replay;
  auto* r = s_->replay = app.add_subcommand(
      "replay", "Play an LCM log into the pipeline; with --wait-for, in lockstep with the named processes");
  r->add_option("log", replay.input_log, "Input LCM log file");
  r->add_option("--lcm-url", replay.lcm_url, "LCM URL to publish on and listen to (empty: LCM_DEFAULT_URL)");
  r->add_option("--wait-for", replay.stages,
                "Process instance names (as in their status) to run in lockstep with; each must run with --lockstep")
      ->delimiter(',');
  r->add_option("--channels", replay.channels, "Regular expression of channels to play (empty: all but STATUS_*)");
  r->add_option("--exclude", replay.exclude,
                "Regular expression of channels not to play (e.g. the stages' own outputs)");
  r->add_option("--record", replay.record_log, "Write every message seen on the bus (but status) to this LCM log");
  r->add_option("--speed", replay.speed, "Without --wait-for: playback speed (1 = real time, 0 = as fast as possible)");
  r->add_option("--start-timeout", replay.start_timeout_s, "Seconds to wait for every --wait-for process to report");
  r->add_option("--step-timeout", replay.step_timeout_s,
                "Seconds to wait for the pipeline to settle after each message");
  r->add_option("--max-events", replay.max_events, "Play at most this many events (0 = all)");
  r->add_flag("--quiet", s_->replay_flags.quiet, "No progress on stderr");
  r->add_flag("--skip-corrupt", replay.skip_corrupt,
              "Skip and count corrupt log events (without it: stop at the first with an error naming its byte offset)");
  s_->replay_layers = std::make_unique<VerbLayers>(r);
  s_->replay_layers->keys({
      {"log", "input.log", true},
      {"--lcm-url", "bus.lcm_url", true},
      {"--wait-for", "lockstep.wait_for", true},
      {"--channels", "input.channels", true},
      {"--exclude", "input.exclude", true},
      {"--record", "output.record", true},
      {"--speed", "playback.speed", false},
      {"--start-timeout", "lockstep.start_timeout_s", false},
      {"--step-timeout", "lockstep.step_timeout_s", false},
      {"--max-events", "input.max_events", false},
      {"--quiet", "output.quiet", false},
      {"--skip-corrupt", "input.skip_corrupt", false},
  });

  SpyOptions& spy = s_->spy_flags.spy;
  auto* s = s_->spy = app.add_subcommand("spy", "Start lcm-spy with the Wingman message types");
  s->add_option("--lcm-url", spy.lcm_url, "LCM URL to listen on (empty: LCM_DEFAULT_URL)");
  s->add_option("--java", spy.java, "Java runtime");
  s->add_option("--types-jar", spy.types_jar, "Jar with the wingman message classes (empty: the built one)");
  s->add_flag("--dry-run", spy.dry_run, "Print the java command instead of running it");
  s_->spy_layers = std::make_unique<VerbLayers>(s);
  s_->spy_layers->keys({
      {"--lcm-url", "bus.lcm_url", true},
      {"--java", "spy.java", true},
      {"--types-jar", "spy.types_jar", true},
      {"--dry-run", "spy.dry_run", false},
  });

  MakeVideoOptions& video = s_->video_flags.video;
  auto* mv = s_->video =
      app.add_subcommand("make-video", "Write a synthetic test clip (MJPG .avi) for the camera driver's file source");
  mv->add_option("output", video.output, "Output .avi file");
  mv->add_option("--frames", video.frames, "Number of frames");
  mv->add_option("--width", video.width, "Width, pixels");
  mv->add_option("--height", video.height, "Height, pixels");
  mv->add_option("--fps", video.fps, "Frames per second");
  s_->video_layers = std::make_unique<VerbLayers>(mv);
  s_->video_layers->keys({
      {"output", "output.file", true},
      {"--frames", "video.frames", false},
      {"--width", "video.width", false},
      {"--height", "video.height", false},
      {"--fps", "video.fps", false},
  });

  auto* li = s_->info =
      app.add_subcommand("loginfo", "Summarize an LCM log: channels, types, counts, time spans, process statuses");
  li->add_option("log", s_->info_flags.log, "LCM log file");
  li->add_option("--snapshot", s_->info_flags.snapshot, "Save the last image_t as this PNG file");
  li->add_flag(
      "--skip-corrupt", s_->info_flags.skip_corrupt,
      "Skip and count corrupt log events (without it: stop at the first with an error naming its byte offset)");
  s_->info_layers = std::make_unique<VerbLayers>(li);
  s_->info_layers->keys({
      {"log", "input.log", true},
      {"--snapshot", "output.snapshot", true},
      {"--skip-corrupt", "input.skip_corrupt", false},
  });
}

LogVerbs::~LogVerbs() = default;

int LogVerbs::run_if_chosen(std::ostream& out, std::ostream& err) {
  if (!*s_->replay && !*s_->spy && !*s_->video && !*s_->info) return -1;
  try {
    if (*s_->replay) {
      int rc = -1;
      auto o = s_->replay_layers->load_or_exit<ReplayVerbOptions>(out, err, &rc);
      if (!o) return rc;
      if (!o->quiet) o->replay.progress = &err;
      const ReplaySummary summary = run_replay(o->replay);
      err << summary.one_line() << std::endl;
      return summary.ok ? 0 : 1;
    }
    if (*s_->spy) {
      int rc = -1;
      const auto o = s_->spy_layers->load_or_exit<SpyVerbOptions>(out, err, &rc);
      return o ? run_spy(o->spy) : rc;
    }
    if (*s_->video) {
      int rc = -1;
      const auto o = s_->video_layers->load_or_exit<MakeVideoVerbOptions>(out, err, &rc);
      if (!o) return rc;
      make_video(o->video);
      err << "wrote " << o->video.frames << " frames to " << o->video.output << std::endl;
      return 0;
    }
    int rc = -1;
    const auto o = s_->info_layers->load_or_exit<LogInfoVerbOptions>(out, err, &rc);
    if (!o) return rc;
    const LogSummary summary = summarize_log(o->log, o->snapshot, o->skip_corrupt, &err);
    out << summary.report() << std::flush;
    if (!o->snapshot.empty() && summary.images_with_pixels > 0)
      out << "last image saved to " << o->snapshot << std::endl;
    return 0;
  } catch (const std::exception& e) {
    err << "wingman: error: " << e.what() << std::endl;
    return 1;
  }
}

}  // namespace wingman::tools
