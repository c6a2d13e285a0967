// SPDX-License-Identifier: MIT
// `wingman load`: the load test's processes through the launcher, /proc sampled in-process, the figures by
// tools/load_summary.py.
#include "wingman/tools/load.hpp"

#include "wingman/geometry/camera_rig.hpp"
#include "wingman/launcher/bus_watch.hpp"
#include "wingman/launcher/launch_setup.hpp"
#include "wingman/launcher/process_group.hpp"
#include "wingman/tools/make_video.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>
#include <wingman/common/config.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <tuple>

namespace wingman::tools {

namespace fs = std::filesystem;
using launcher::process;

namespace {

using Clock = std::chrono::steady_clock;

constexpr double kStartTimeoutS = 180.0;            // every process's first heartbeat (each detector loads the model)
const char* kFixedStartUtime = "1700000000000000";  // fast cameras: frames stamped from here (deterministic)

/// A counter of the `Udp:` lines of /proc/net/snmp (this network namespace's), -1 when absent.
int64_t udp_counter(const std::string& name) {
  std::ifstream in("/proc/net/snmp");
  std::vector<std::string> header;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("Udp:", 0) != 0) continue;
    std::istringstream words(line);
    std::vector<std::string> fields;
    for (std::string w; words >> w;) fields.push_back(w);
    if (header.empty()) {
      header = fields;
      continue;
    }
    for (size_t i = 1; i < header.size() && i < fields.size(); ++i) {
      if (header[i] == name) return std::stoll(fields[i]);
    }
  }
  return -1;
}

/// One /proc sample of `pid`: RSS (KiB, VmRSS) and CPU seconds (utime + stime, all threads); false when it is gone.
bool sample_process(pid_t pid, int64_t* rss_kib, double* cpu_s) {
  std::ifstream status(fmt::format("/proc/{}/status", pid));
  bool have_rss = false;
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmRSS:", 0) == 0) {
      *rss_kib = std::stoll(line.substr(6));
      have_rss = true;
    }
  }
  std::ifstream stat(fmt::format("/proc/{}/stat", pid));
  std::string text;
  std::getline(stat, text);
  const size_t close = text.rfind(") ");
  if (!have_rss || close == std::string::npos) return false;
  std::istringstream rest(text.substr(close + 2));  // state ppid pgrp ... (field 3 on)
  std::vector<std::string> f;
  for (std::string w; rest >> w;) f.push_back(w);
  if (f.size() < 13) return false;
  const double tck = static_cast<double>(::sysconf(_SC_CLK_TCK));
  *cpu_s = (std::stod(f[11]) + std::stod(f[12])) / tck;  // utime, stime: fields 14 and 15
  return true;
}

}  // namespace

double LoadOptions::effective_duration_s() const { return duration_s > 0.0 ? duration_s : (soak ? 600.0 : 30.0); }

double LoadOptions::effective_warmup_s() const {
  return warmup_s > 0.0 ? warmup_s : (effective_duration_s() <= 180.0 ? 30.0 : 60.0);
}

std::vector<std::string> LoadOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (mode != "realtime" && mode != "replay") p.push_back(problem("load.mode", mode, "must be realtime or replay"));
  if (soak && mode == "replay") p.push_back(problem("load.soak", "true", "runs in realtime mode; drop --mode replay"));
  if (cameras < 1 || cameras > 4) p.push_back(problem("load.cameras", cameras, "must be 1..4"));
  if (!(duration_s >= 0.0)) p.push_back(problem("load.duration_s", duration_s, "must be >= 0 seconds"));
  if (!(warmup_s >= 0.0)) p.push_back(problem("load.warmup_s", warmup_s, "must be >= 0 seconds"));
  if (!(sample_period_s > 0.0)) p.push_back(problem("load.sample_period_s", sample_period_s, "must be > 0 seconds"));
  if (replay_frames < 1) p.push_back(problem("load.replay_frames", replay_frames, "must be at least 1"));
  if (encoding != "raw" && encoding != "mjpeg") p.push_back(problem("load.encoding", encoding, "must be raw or mjpeg"));
  if (jpeg_quality < 1 || jpeg_quality > 100)
    p.push_back(problem("load.jpeg_quality", jpeg_quality, "must be in 1..100"));
  if (max_width != 0 && (max_width < 16 || max_width > 1280))
    p.push_back(problem("load.max_width", max_width, "must be 0 (1280, full size) or in 16..1280"));
  if (rig.empty()) p.push_back(problem("load.rig", rig, "must name a camera rig file (config/rigs/surround4.yaml)"));
  if (!(max_p99_s > 0.0)) p.push_back(problem("checks.max_p99_s", max_p99_s, "must be > 0 seconds"));
  if (!(max_rss_growth_pct >= 0.0))
    p.push_back(problem("checks.max_rss_growth_pct", max_rss_growth_pct, "must be a percentage >= 0"));
  if (soak && effective_duration_s() < effective_warmup_s() + 20.0) {
    p.push_back(problem("load.duration_s", effective_duration_s(),
                        fmt::format("a soak needs at least the warm-up ({} s) plus 20 s", effective_warmup_s())));
  }
  return p;
}

std::vector<std::string> load_process_sets(const std::string& exe, int camera, const std::string& clip, bool realtime,
                                           int max_frames, bool detector_realtime, const LoadOptions& o) {
  if (exe == "wingman-detector") {
    return {"--set",
            fmt::format("input={{channel: IMAGE_CAM{}, mode: {}}}", camera, detector_realtime ? "realtime" : "replay"),
            "--set",
            fmt::format("output.channel=DETECTIONS_CAM{}", camera),
            "--set",
            "model={cfg: \"builtin:wingman-small\", weights: \"builtin:wingman-small\"}"};
  }
  if (exe == "wingman-localizer") {  // one localizer fuses every camera of the rig (DETECTIONS_CAM<n>) on TARGETS
    return {"--set", fmt::format("cameras.rig=\"{}\"", fs::absolute(o.rig).string()), "--set", "output.channel=TARGETS",
            "--set", fmt::format("camera.scale_to_image={}", o.max_width > 0)};
  }
  if (exe == "wingman-camera-driver") {  // the clip in a loop at 30 fps
    std::vector<std::string> sets = {
        "--set",
        "source.kind=file",
        "--set",
        fmt::format("output={{channel: IMAGE_CAM{}, camera_id: {}, encoding: {}, jpeg_quality: {}, max_width: {}}}",
                    camera, camera, o.encoding, o.jpeg_quality, o.max_width),
        "--set",
        fmt::format("file={{path: \"{}\", mode: {}, fps: 30.0, loop: true}}", clip, realtime ? "realtime" : "fast")};
    // fast: the replay log's frames, stamped from a fixed start time (deterministic); realtime: by the wall clock.
    if (!realtime) {
      launcher::append_args(sets, {"--set", std::string("file.start_utime=") + kFixedStartUtime, "--set",
                                   fmt::format("output.max_frames={}", max_frames)});
    }
    return sets;
  }
  if (exe == "wingman-follower-ctrl") {  // it follows the fused targets
    return {"--set", "input={targets_channel: TARGETS, detections_channel: DETECTIONS_CAM0}"};
  }
  throw std::invalid_argument("load_process_sets: no load settings for " + exe);
}

namespace {

/// One chain per camera of the rig: chain i publishes DETECTIONS_CAM<i>, so the rig's cameras must read exactly
/// DETECTIONS_CAM0 .. DETECTIONS_CAM<cameras - 1> (else the localizer waits on cameras nobody plays, or drops a chain).
/// Throws common::ConfigError naming the rig file (unreadable, bad) and std::invalid_argument naming both keys.
void check_rig_matches_chains(const LoadOptions& o) {
  const geometry::CameraRig rig = geometry::load_camera_rig(o.rig);
  std::vector<std::string> want, have;
  for (int i = 0; i < o.cameras; ++i) want.push_back(fmt::format("DETECTIONS_CAM{}", i));
  for (const geometry::RigCamera& c : rig.cameras) have.push_back(c.detections_channel);
  std::sort(want.begin(), want.end());
  std::sort(have.begin(), have.end());
  if (want != have) {
    throw std::invalid_argument(fmt::format(
        "load.cameras = {} and load.rig = {}: the rig's cameras read {}, the load test's {} chain(s) publish {}: one "
        "chain per rig camera (give --cameras {} or a rig of {} camera(s) with camera ids 0..{}: --set load.rig=FILE)",
        o.cameras, o.rig, fmt::join(have, ", "), o.cameras, fmt::join(want, ", "), rig.cameras.size(), o.cameras,
        o.cameras - 1));
  }
}

}  // namespace

int run_load(const LoadOptions& o, std::ostream& out, std::ostream& err) {
  if (const auto problems = o.validate(); !problems.empty()) throw std::invalid_argument(problems.front());
  check_rig_matches_chains(o);
  const bool replay = o.mode == "replay";
  const double duration_s = o.effective_duration_s();
  const std::string bin = launcher::executables_dir(
      o.bin_dir, {"wingman-camera-driver", "wingman-detector", "wingman-localizer", "wingman-follower-ctrl"});
  auto exe = [&](const std::string& name) { return (fs::path(bin) / name).string(); };
  const std::string url = replay ? "" : launcher::private_bus_url(o.lcm_url, "wingman load", "tools/load_test.sh");
  // load_summary.py decodes with the generated Python types: the build tree's (build/python beside the binaries) or
  // an installed prefix's; checked now, not after the run.
  const fs::path prefix = fs::path(bin).parent_path();
  const char* py_env = std::getenv("PYTHONPATH");
  launcher::ProcessSpec summary_base = process("load_summary.py", {"python3", o.summary_script});
  summary_base.env = {"PYENV_VERSION=system", fmt::format("PYTHONPATH={}:{}{}", (prefix / "python").string(),
                                                          (prefix / "lib/python3/dist-packages").string(),
                                                          py_env && *py_env ? std::string(":") + py_env : "")};
  auto summary = [&](std::vector<std::string> args) {
    launcher::ProcessSpec s = summary_base;
    launcher::append_args(s.argv, args);
    return s;
  };
  launcher::ProcessGroup group;
  {
    launcher::ProcessSpec check = summary({"--help"});
    check.stdout_path = "/dev/null";
    if (group.run(check) != 0) throw std::invalid_argument(o.summary_script + " cannot run (above)");
  }
  // The processes' threads: PoCL pinned, OpenMP and OpenBLAS quiet (each only where the caller did not choose).
  ::setenv("POCL_AFFINITY", "1", 0);
  ::setenv("OMP_WAIT_POLICY", "PASSIVE", 0);
  ::setenv("OPENBLAS_NUM_THREADS", "1", 0);

  const fs::path out_dir =
      fs::absolute(o.out.empty() ? (fs::path("build") / "load" / (o.soak ? "soak" : o.mode)) : fs::path(o.out));
  fs::create_directories(out_dir);
  const std::string clip = (out_dir / "clip_1280x720.avi").string();
  std::error_code ec;
  if (!fs::exists(clip, ec) || fs::file_size(clip, ec) == 0) {
    MakeVideoOptions video;
    video.output = clip + ".tmp.avi";
    video.width = 1280;
    video.height = 720;
    video.frames = 90;
    video.fps = 30;
    make_video(video);
    fs::rename(video.output, clip);
  }

  // Every process's merged configuration, as its loader read it (a record of the run).
  const bool fast_cameras = replay;
  std::vector<std::tuple<std::string, int, std::string>> printed;  // (executable, camera, file)
  for (int i = 0; i < o.cameras; ++i) {
    printed.emplace_back("wingman-detector", i, fmt::format("detector_{}.yaml", i));
    printed.emplace_back("wingman-camera-driver", i, fmt::format("camera_{}.yaml", i));
  }
  printed.emplace_back("wingman-localizer", 0, "localizer.yaml");  // checks the rig file too
  printed.emplace_back("wingman-follower-ctrl", 0, "follower_ctrl.yaml");
  for (const auto& [name, i, file] : printed) {
    launcher::ProcessSpec print = process(name, {exe(name)});
    launcher::append_args(print.argv, load_process_sets(name, i, clip, !fast_cameras, o.replay_frames, !replay, o));
    print.argv.push_back("--print-config");
    print.stdout_path = (out_dir / file).string();
    if (group.run(print) != 0) {
      err << "load_test: FAILED: " << name << " rejects its settings (above)" << std::endl;
      return 1;
    }
  }
  launcher::StopSignals signals;

  // ------------------------------------------------------------------------------------------------------ replay
  if (replay) {
    const std::string images = (out_dir / "images.lcmlog").string();
    fs::remove(images, ec);
    for (int i = 0; i < 4; ++i) fs::remove(out_dir / fmt::format("detections_{}.lcmlog", i), ec);
    // The same four-camera input as real time, recorded: each camera in turn appends its frames to one log, stamped
    // from a fixed start time (fast mode: deterministic), as the cameras would have captured them together.
    for (int i = 0; i < o.cameras; ++i) {
      launcher::ProcessSpec cam =
          process(fmt::format("camera_{}", i), {exe("wingman-camera-driver"), "--name", fmt::format("camera_{}", i)});
      launcher::append_args(cam.argv,
                            load_process_sets("wingman-camera-driver", i, clip, false, o.replay_frames, false, o));
      launcher::append_args(
          cam.argv, {"--log-level", "warn", "--lcm-out", fmt::format("file://{}?mode={}", images, i == 0 ? "w" : "a")});
      if (const int rc = group.run(cam); rc != 0) {
        err << "load_test: FAILED: camera_" << i << " exited " << rc << std::endl;
        return 1;
      }
    }
    const auto mib = static_cast<int64_t>(std::ceil(static_cast<double>(fs::file_size(images)) / (1024.0 * 1024.0)));
    out << fmt::format(
               "load_test: replay: {} cameras x {} frames of 1280x720 {} in {} ({} MiB); {} detectors read it "
               "file to file, in parallel",
               o.cameras, o.replay_frames,
               o.encoding == "mjpeg" ? fmt::format("MJPEG (quality {})", o.jpeg_quality) : std::string("BGR8"), images,
               mib, o.cameras)
        << std::endl;
    const auto t0 = Clock::now();
    std::vector<size_t> detectors;
    std::vector<std::string> detection_logs;
    for (int i = 0; i < o.cameras; ++i) {
      detection_logs.push_back((out_dir / fmt::format("detections_{}.lcmlog", i)).string());
      launcher::ProcessSpec det =
          process(fmt::format("detector_{}", i), {exe("wingman-detector"), "--name", fmt::format("detector_{}", i)});
      launcher::append_args(det.argv, load_process_sets("wingman-detector", i, clip, false, 0, false, o));
      launcher::append_args(det.argv, {"--log-level", "warn", "--lcm-in", fmt::format("file://{}?speed=0", images),
                                       "--lcm-out", fmt::format("file://{}?mode=w", detection_logs.back())});
      detectors.push_back(group.start(det));
    }
    bool failed = false;
    for (const size_t d : detectors) failed = group.wait(d) != 0 || failed;
    out << "load_test: replay: detectors done in "
        << static_cast<int>(std::chrono::duration<double>(Clock::now() - t0).count()) << " s" << std::endl;
    if (failed) {
      err << "load_test: FAILED: a detector exited non-zero" << std::endl;
      return 1;
    }
    std::vector<std::string> args = {"replay", images};
    launcher::append_args(args, detection_logs);
    launcher::append_args(args, {"--json", (out_dir / "summary.json").string()});
    const int rc = group.run(summary(args)) == 0 ? 0 : 1;
    if (rc == 0) fs::remove(images, ec);  // large and made anew by every run: kept only when a check failed
    return rc;
  }

  // ---------------------------------------------------------------------------------------------------- realtime
  const std::string log = (out_dir / "load.lcmlog").string();
  const std::string proc_csv = (out_dir / "processes.csv").string();
  fs::remove(log, ec);
  fs::remove(proc_csv, ec);
  out << fmt::format(
             "load_test: {} cameras x 1280x720 x 30 fps ({} on the bus) for {} s on {} (private network namespace), "
             "one localizer fusing the rig {}, output in {}",
             o.cameras,
             fmt::format("{}{}", o.encoding == "mjpeg" ? fmt::format("MJPEG, quality {}", o.jpeg_quality) : "raw BGR8",
                         o.max_width > 0 ? fmt::format(", downscaled to {} px wide", o.max_width) : ""),
             duration_s, url, fs::absolute(o.rig).string(), out_dir.string())
      << std::endl;
  const size_t logger = group.start(process("lcm-logger", {"lcm-logger", "--lcm-url=" + url, "--force", "--quiet",
                                                           "--channel=IMAGE_.*", "--invert-channels", log}));
  std::vector<size_t> cams, rest;  // stopped in this order: the sources first
  std::map<size_t, std::string> names;
  auto start = [&](const std::string& name, const std::string& exe_name, const std::vector<std::string>& sets) {
    launcher::ProcessSpec spec =
        process(name, {exe(exe_name), "--name", name, "--lcm-url", url, "--log-level", "info"});
    launcher::append_args(spec.argv, sets);
    spec.stderr_path = (out_dir / (name + ".stderr")).string();
    const size_t i = group.start(spec);
    names[i] = name;
    return i;
  };
  for (int i = 0; i < o.cameras; ++i) {
    rest.push_back(start(fmt::format("detector_{}", i), "wingman-detector",
                         load_process_sets("wingman-detector", i, clip, true, 0, true, o)));
  }
  rest.push_back(
      start("localizer", "wingman-localizer", load_process_sets("wingman-localizer", 0, clip, true, 0, true, o)));
  rest.push_back(start("follower_ctrl", "wingman-follower-ctrl",
                       load_process_sets("wingman-follower-ctrl", 0, clip, true, 0, true, o)));

  int rc = 0;
  // Ends the run: the sources first, the detectors' frame in hand given time, then the rest (each publishes a final
  // STOPPING heartbeat with its counts), then the logger.
  auto stop_all = [&] {
    group.stop(cams, launcher::ProcessGroup::kDefaultGraceS);
    std::this_thread::sleep_for(std::chrono::seconds(3));
    group.stop(rest, launcher::ProcessGroup::kDefaultGraceS);
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    group.stop({logger}, launcher::ProcessGroup::kDefaultGraceS);
  };
  // A process that has ended: named with the end of its stderr; true.
  auto exited = [&](const char* when) {
    for (const auto& [i, name] : names) {
      if (const auto code = group.poll(i)) {
        err << "load_test: FAILED: " << name << " exited " << *code << " " << when << "; its stderr:\n"
            << launcher::output_tail((out_dir / (name + ".stderr")).string(), 5) << std::flush;
        return true;
      }
    }
    return false;
  };
  // Start-up takes seconds (each detector loads the model and picks its backend): every process publishes a first
  // heartbeat once it listens.
  {
    std::vector<std::string> wanted;
    for (const auto& [i, name] : names) wanted.push_back(name);
    launcher::BusWatch bus(url);
    bool ended = false;
    const auto missing = bus.wait_for_status(wanted, kStartTimeoutS, [&] {
      ended = ended || exited("during start-up");
      return ended || signals.requested();
    });
    if (ended || signals.requested() || !missing.empty()) {
      if (!ended && !signals.requested())
        err << "load_test: FAILED: not every process reported within " << kStartTimeoutS << " s" << std::endl;
      stop_all();
      return signals.requested() ? 130 : 1;
    }
  }
  for (int i = 0; i < o.cameras; ++i) {
    cams.push_back(start(fmt::format("camera_{}", i), "wingman-camera-driver",
                         load_process_sets("wingman-camera-driver", i, clip, true, 0, true, o)));
  }
  out << "load_test: pipeline up; cameras playing" << std::endl;
  // Every process's RSS and CPU time from /proc into the CSV, every sample_period_s, until the end of the run.
  std::ofstream csv(proc_csv);
  csv << "t_s,process,pid,rss_kib,cpu_s\n";
  const auto t0 = Clock::now();
  auto since_s = [&] { return std::chrono::duration<double>(Clock::now() - t0).count(); };
  const double end_s = std::ceil(duration_s);
  double next_sample_s = 0.0;
  while (since_s() < end_s) {
    if (signals.requested()) {
      err << "load_test: stopped by signal " << signals.signal() << std::endl;
      stop_all();
      return 130;
    }
    if (exited("during the run")) {
      stop_all();
      return 1;
    }
    if (since_s() >= next_sample_s) {
      const double t_s = since_s();
      for (const auto& [i, name] : names) {
        int64_t rss = 0;
        double cpu = 0.0;
        if (sample_process(group.pid(i), &rss, &cpu))
          csv << fmt::format("{:.2f},{},{},{},{:.2f}\n", t_s, name, group.pid(i), rss, cpu);
      }
      csv.flush();
      next_sample_s += o.sample_period_s;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  csv.close();
  stop_all();

  // The namespace is ours alone: its UDP counters are this run's. RcvbufErrors: datagrams the kernel dropped because a
  // socket's receive buffer was full (a reader that did not keep up), the only way a published frame is lost here.
  const int64_t rcvbuf_errors = udp_counter("RcvbufErrors");
  out << "load_test: UDP in this namespace: " << udp_counter("InDatagrams") << " datagrams received, " << rcvbuf_errors
      << " dropped on full receive buffers" << std::endl;
  for (const auto& [i, name] : names) {
    std::ifstream in(out_dir / (name + ".stderr"));
    bool backend_shown = false;
    int warnings = 0;
    for (std::string line; std::getline(in, line);) {
      if (!backend_shown && line.find("backend") != std::string::npos) {
        out << "load_test: " << name << ": " << line << '\n';
        backend_shown = true;
      }
      if (warnings < 3 && (line.find("] warning:") != std::string::npos || line.find("] error:") != std::string::npos ||
                           line.find("] critical:") != std::string::npos)) {
        out << "load_test: " << name << ": " << line << '\n';
        ++warnings;
      }
    }
  }
  out << std::endl;
  std::vector<std::string> args = {"realtime",
                                   log,
                                   "--cameras",
                                   std::to_string(o.cameras),
                                   "--proc-csv",
                                   proc_csv,
                                   "--max-p99-s",
                                   fmt::format("{}", o.max_p99_s),
                                   "--udp-rcvbuf-errors",
                                   std::to_string(rcvbuf_errors)};
  if (o.report_only) args.push_back("--report-only");
  launcher::append_args(args, {"--json", (out_dir / "summary.json").string()});
  if (group.run(summary(args)) != 0) rc = 1;
  if (o.soak) {
    out << std::endl;
    std::vector<std::string> soak_args = {"soak",
                                          log,
                                          "--proc-csv",
                                          proc_csv,
                                          "--warmup-s",
                                          fmt::format("{}", o.effective_warmup_s()),
                                          "--max-rss-growth-pct",
                                          fmt::format("{}", o.max_rss_growth_pct)};
    if (o.report_only) soak_args.push_back("--report-only");
    launcher::append_args(soak_args, {"--json", (out_dir / "soak.json").string()});
    if (group.run(summary(soak_args)) != 0) rc = 1;
  }
  out << "load_test: log " << log << ", samples " << proc_csv << ", figures " << (out_dir / "summary.json").string()
      << std::endl;
  return rc;
}

}  // namespace wingman::tools
