// SPDX-License-Identifier: MIT
// The log verbs' command lines: `wingman replay`, `spy`, `make-video` and `loginfo`.
#include "wingman/tools/log_cli.hpp"

#include "wingman/tools/log_info.hpp"
#include "wingman/tools/make_video.hpp"
#include "wingman/tools/replay.hpp"
#include "wingman/tools/spy.hpp"

#include <exception>
#include <string>

#include <CLI/CLI.hpp>

namespace wingman::tools {

struct LogVerbs::State {
  CLI::App* replay = nullptr;
  ReplayOptions replay_options;
  bool replay_quiet = false;
  CLI::App* spy = nullptr;
  SpyOptions spy_options;
  CLI::App* video = nullptr;
  MakeVideoOptions video_options;
  CLI::App* info = nullptr;
  std::string info_log, info_snapshot;
  bool info_skip_corrupt = false;
};

LogVerbs::LogVerbs(CLI::App& app) : s_(std::make_unique<State>()) {
  ReplayOptions& replay = s_->replay_options;
  auto* r = s_->replay = app.add_subcommand(
      "replay", "Play an LCM log into the pipeline; with --wait-for, in lockstep with the named processes");
  r->add_option("log", replay.input_log, "Input LCM log file")->required();
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
  r->add_flag("--quiet", s_->replay_quiet, "No progress on stderr");
  r->add_flag("--skip-corrupt", replay.skip_corrupt,
              "Skip and count corrupt log events (without it: stop at the first with an error naming its byte offset)");

  SpyOptions& spy = s_->spy_options;
  auto* s = s_->spy = app.add_subcommand("spy", "Start lcm-spy with the Wingman message types");
  s->add_option("--lcm-url", spy.lcm_url, "LCM URL to listen on (empty: LCM_DEFAULT_URL)");
  s->add_option("--java", spy.java, "Java runtime");
  s->add_option("--types-jar", spy.types_jar, "Jar with the wingman message classes (empty: the built one)");
  s->add_flag("--dry-run", spy.dry_run, "Print the java command instead of running it");

  MakeVideoOptions& video = s_->video_options;
  auto* mv = s_->video =
      app.add_subcommand("make-video", "Write a synthetic test clip (MJPG .avi) for the camera driver's file source");
  mv->add_option("output", video.output, "Output .avi file")->required();
  mv->add_option("--frames", video.frames, "Number of frames");
  mv->add_option("--width", video.width, "Width, pixels");
  mv->add_option("--height", video.height, "Height, pixels");
  mv->add_option("--fps", video.fps, "Frames per second");

  auto* li = s_->info =
      app.add_subcommand("loginfo", "Summarize an LCM log: channels, types, counts, time spans, process statuses");
  li->add_option("log", s_->info_log, "LCM log file")->required();
  li->add_option("--snapshot", s_->info_snapshot, "Save the last image_t as this PNG file");
  li->add_flag(
      "--skip-corrupt", s_->info_skip_corrupt,
      "Skip and count corrupt log events (without it: stop at the first with an error naming its byte offset)");
}

LogVerbs::~LogVerbs() = default;

int LogVerbs::run_if_chosen(std::ostream& out, std::ostream& err) {
  if (!*s_->replay && !*s_->spy && !*s_->video && !*s_->info) return -1;
  try {
    if (*s_->replay) {
      ReplayOptions& o = s_->replay_options;
      if (!s_->replay_quiet) o.progress = &err;
      const ReplaySummary summary = run_replay(o);
      err << summary.one_line() << std::endl;
      return summary.ok ? 0 : 1;
    }
    if (*s_->spy) return run_spy(s_->spy_options);
    if (*s_->video) {
      make_video(s_->video_options);
      err << "wrote " << s_->video_options.frames << " frames to " << s_->video_options.output << std::endl;
      return 0;
    }
    const LogSummary summary = summarize_log(s_->info_log, s_->info_snapshot, s_->info_skip_corrupt, &err);
    out << summary.report() << std::flush;
    if (!s_->info_snapshot.empty() && summary.images_with_pixels > 0)
      out << "last image saved to " << s_->info_snapshot << std::endl;
    return 0;
  } catch (const std::exception& e) {
    err << "wingman: error: " << e.what() << std::endl;
    return 1;
  }
}

}  // namespace wingman::tools
