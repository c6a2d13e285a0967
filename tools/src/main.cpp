// SPDX-License-Identifier: MIT
// `wingman`: the tools CLI. Verbs: replay (deterministic log player), spy (lcm-spy with our types).
#include "wingman/tools/replay.hpp"
#include "wingman/tools/spy.hpp"

#include <CLI/CLI.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <iostream>

int main(int argc, char** argv) {
  using namespace wingman::tools;
  CLI::App app{"Wingman tools: replay logs through the pipeline, monitor it", "wingman"};
  app.require_subcommand(1);

  ReplayOptions replay;
  auto* r = app.add_subcommand("replay", "Play an LCM log into the pipeline; with --wait-for, in lockstep with the named processes");
  r->add_option("log", replay.input_log, "Input LCM log file")->required();
  r->add_option("--lcm-url", replay.lcm_url, "LCM URL to publish on and listen to (default: LCM_DEFAULT_URL)");
  r->add_option("--wait-for", replay.stages,
                "Process instance names (as in their status) to run in lockstep with; each must run with --lockstep")
      ->delimiter(',');
  r->add_option("--channels", replay.channels, "Regular expression of channels to play (default: all but STATUS_*)");
  r->add_option("--exclude", replay.exclude, "Regular expression of channels not to play (e.g. the stages' own outputs)");
  r->add_option("--record", replay.record_log, "Write every message seen on the bus (but status) to this LCM log");
  r->add_option("--speed", replay.speed, "Without --wait-for: playback speed (1 = real time, 0 = as fast as possible)");
  r->add_option("--start-timeout", replay.start_timeout_s, "Seconds to wait for every --wait-for process to report");
  r->add_option("--step-timeout", replay.step_timeout_s, "Seconds to wait for the pipeline to settle after each message");
  r->add_option("--max-events", replay.max_events, "Play at most this many events (0 = all)");

  SpyOptions spy;
  auto* s = app.add_subcommand("spy", "Start lcm-spy with the Wingman message types");
  s->add_option("--lcm-url", spy.lcm_url, "LCM URL to listen on (default: LCM_DEFAULT_URL)");
  s->add_option("--java", spy.java, "Java runtime (default: java)");
  s->add_option("--types-jar", spy.types_jar, "Jar with the wingman message classes (default: the built one)");
  s->add_flag("--dry-run", spy.dry_run, "Print the java command instead of running it");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() != 0) {
      std::cerr << "wingman: error: " << e.what() << " (see --help)" << std::endl;
      return 2;
    }
    return app.exit(e);
  }
  auto logger = spdlog::stderr_color_st("wingman");
  logger->set_pattern("%Y-%m-%dT%H:%M:%S.%e [%n] %^%l%$: %v");
  spdlog::set_default_logger(logger);

  try {
    if (*r) {
      const ReplaySummary summary = run_replay(replay);
      std::cerr << summary.one_line() << std::endl;
      return summary.ok ? 0 : 1;
    }
    if (*s) return run_spy(spy);
  } catch (const std::exception& e) {
    std::cerr << "wingman: error: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
