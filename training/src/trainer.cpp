// SPDX-License-Identifier: MIT
// Trainer: data order, augmentation, forward/backward over subdivisions, SGD, checkpoints, validation.
#include "wingman/training/trainer.hpp"

#include "wingman/training/darknet_torch.hpp"
#include "wingman/training/detection_loss.hpp"
#include "wingman/training/seeded_random.hpp"
#include "wingman/training/yolo_dataset.hpp"

#include <wingman/common/progress.hpp>
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/detector/darknet_weights.hpp>
#include <wingman/detector/nms.hpp>
#include <wingman/detector/region_decode.hpp>

#include <ATen/Parallel.h>
#include <fmt/format.h>
#include <torch/optim/sgd.h>
#include <torch/serialize/archive.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <sstream>
#include <stdexcept>

namespace wingman::training {

namespace fs = std::filesystem;
using detector::LayerType;

namespace {

constexpr float kValPThresh = 0.005f;  // keep nearly every box for the PR curve
constexpr float kValNms = 0.45f;
constexpr const char* kCheckpointName = "checkpoint.pt";

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw detector::DarknetFormatError(fmt::format("{}: cannot open the .cfg file", path));
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

torch::Tensor bytes_tensor(const std::string& s) {
  torch::Tensor t = torch::empty({static_cast<int64_t>(s.size())}, torch::kUInt8);
  if (!s.empty()) std::memcpy(t.data_ptr<uint8_t>(), s.data(), s.size());
  return t;
}

std::string tensor_bytes(const torch::Tensor& t) {
  const torch::Tensor c = t.contiguous();
  return std::string(reinterpret_cast<const char*>(c.data_ptr<uint8_t>()), static_cast<size_t>(c.numel()));
}

}  // namespace

std::string TrainProgress::one_line() const {
  return fmt::format(
      "iter {}/{}: loss {:.4f} avg {:.4f} (coord {:.4f} obj {:.4f} noobj {:.4f} cls {:.4f}) IoU {:.3f} truths {} "
      "lr {:.3g} {:.2f} img/s (data {:.0f}%) elapsed {} ETA {}",
      iteration, max_batches, loss, loss_avg, coord, object, noobject, cls, mean_iou, truths, learning_rate,
      images_per_s, 100.0 * data_share, common::duration_text(elapsed_s), common::duration_text(eta_s));
}

std::string TrainSummary::one_line() const {
  return fmt::format("{} at iteration {}/{} (started at {}): loss {:.4f} -> avg {:.4f}, {:.2f} img/s, weights {}",
                     interrupted ? "interrupted" : "done", iteration, max_batches, start_iteration, first_loss,
                     loss_avg, images_per_s, weights);
}

std::string TrainSummary::report() const {
  std::string s = one_line() + "\n";
  s += fmt::format("checkpoint: {}\nelapsed: {}\n", checkpoint, common::duration_text(elapsed_s));
  if (!raw_weights.empty()) s += fmt::format("trained weights (not averaged): {}\n", raw_weights);
  if (validation) s += "validation:\n" + validation->report();
  return s;
}

struct Trainer::Impl {
  TrainOptions o;
  std::string cfg_text;
  detector::DarknetModel model;
  YoloDataset train;
  YoloDataset val;  // the val_split, read at construction (empty without one)
  DarknetNet net{nullptr};
  DarknetNet average{nullptr};  // the weight average (o.ema), in eval mode; null when off
  int init_layers = 0;          // [convolutional] layers taken from o.init_weights
  std::unique_ptr<torch::optim::SGD> optimizer;
  int64_t iteration = 0;
  double loss_avg = -1.0;
  std::string stem;
  int64_t perm_epoch = -1;
  std::vector<size_t> perm;

  std::string out(const std::string& name) const { return (fs::path(o.out_dir) / name).string(); }

  /// Dataset index of training sample g (g-th image since the start of training).
  size_t sample_index(int64_t g) {
    const int64_t n = static_cast<int64_t>(train.images.size());
    const int64_t epoch = g / n;
    if (epoch != perm_epoch) {
      perm.resize(static_cast<size_t>(n));
      std::iota(perm.begin(), perm.end(), 0);
      SeededRandom rng(mix_seed(o.seed, static_cast<uint64_t>(epoch), 0x5eed));
      for (size_t i = perm.size(); i > 1; --i) std::swap(perm[i - 1], perm[rng.below(i)]);  // Fisher-Yates
      perm_epoch = epoch;
    }
    return perm[static_cast<size_t>(g % n)];
  }

  cv::Mat read_image(size_t index) const {
    const std::string& path = train.images[index].image_path;
    cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR);
    if (bgr.empty()) throw DatasetError(fmt::format("{}: cannot read the image", path));
    return bgr;
  }

  /// Fills `input` (per x C x H x W) and `truths` with sub-batch `sub` of iteration `it`.
  void load_sub_batch(int64_t it, int sub, std::vector<float>& input, std::vector<std::vector<LabeledBox>>& truths) {
    const int per = o.batch / o.subdivisions;
    const cv::Size net_size(model.net.width, model.net.height);
    const size_t plane = static_cast<size_t>(3) * net_size.area();
    input.resize(plane * static_cast<size_t>(per));
    truths.assign(static_cast<size_t>(per), {});
    for (int k = 0; k < per; ++k) {
      const int64_t g = it * o.batch + static_cast<int64_t>(sub) * per + k;
      const size_t index = sample_index(g);
      SeededRandom pick(mix_seed(o.seed, static_cast<uint64_t>(g), 1));
      AugmentedImage a;
      if (o.augment.mosaic > 0 && pick.chance(o.augment.mosaic)) {
        std::vector<cv::Mat> imgs;
        std::vector<size_t> idx = {index};
        for (int m = 0; m < 3; ++m) idx.push_back(static_cast<size_t>(pick.below(train.images.size())));
        for (size_t i : idx) imgs.push_back(read_image(i));
        std::vector<const cv::Mat*> ip;
        std::vector<const std::vector<LabeledBox>*> bp;
        for (size_t m = 0; m < 4; ++m) {
          ip.push_back(&imgs[m]);
          bp.push_back(&train.images[idx[m]].boxes);
        }
        a = augment_mosaic(ip, bp, net_size, o.augment, mix_seed(o.seed, static_cast<uint64_t>(g), 2));
      } else {
        a = augment_image(read_image(index), train.images[index].boxes, net_size, o.augment,
                          mix_seed(o.seed, static_cast<uint64_t>(g), 2));
      }
      bgr_to_chw(a.bgr, input.data() + plane * static_cast<size_t>(k));
      truths[static_cast<size_t>(k)] = std::move(a.boxes);
    }
  }

  /// The network the run exports and validates: the weight average when there is one.
  DarknetNet exported() const { return average ? average : net; }

  void save_weights(const std::string& path, const DarknetNet& which) const {
    detector::DarknetModel m = model;
    which->store_weights(m);
    m.seen = static_cast<uint64_t>(iteration) * static_cast<uint64_t>(o.batch);
    detector::save_darknet_weights(m, path);
  }

  void save_checkpoint() const {
    torch::serialize::OutputArchive a;
    net->save(a);
    torch::serialize::OutputArchive opt;
    optimizer->save(opt);
    a.write("optimizer", opt);
    a.write("iteration", torch::tensor(iteration, torch::kInt64));
    a.write("loss_avg", torch::tensor(loss_avg, torch::kFloat64));
    a.write("seed", torch::tensor(static_cast<int64_t>(o.seed), torch::kInt64));
    a.write("batch", torch::tensor(static_cast<int64_t>(o.batch), torch::kInt64));
    a.write("train_images", torch::tensor(static_cast<int64_t>(train.images.size()), torch::kInt64));
    a.write("cfg_text", bytes_tensor(cfg_text));
    if (average) {
      torch::serialize::OutputArchive avg;
      average->save(avg);
      a.write("weight_average", avg);
      a.write("ema_decay", torch::tensor(o.ema.decay, torch::kFloat64));
      a.write("ema_ramp", torch::tensor(o.ema.ramp, torch::kFloat64));
    }
    const std::string path = out(kCheckpointName);
    const std::string tmp = path + ".tmp";
    a.save_to(tmp);
    std::error_code ec;
    fs::rename(tmp, path, ec);
    if (ec) throw std::runtime_error(fmt::format("{}: cannot write the checkpoint: {}", path, ec.message()));
  }

  void load_checkpoint() {
    const std::string path = out(kCheckpointName);
    if (!fs::is_regular_file(path))
      throw std::runtime_error(fmt::format("{}: no checkpoint to resume from (train without --resume first)", path));
    torch::serialize::InputArchive a;
    try {
      a.load_from(path);
    } catch (const std::exception& e) {
      throw std::runtime_error(fmt::format("{}: not a readable checkpoint: {}", path, e.what()));
    }
    torch::Tensor t;
    a.read("cfg_text", t);
    if (tensor_bytes(t) != cfg_text)
      throw std::runtime_error(
          fmt::format("{}: made with a different .cfg than {} (the network and training "
                      "settings must not change on resume)",
                      path, o.cfg));
    auto read_int = [&](const char* key) {
      torch::Tensor v;
      a.read(key, v);
      return v.item<int64_t>();
    };
    const int64_t seed = read_int("seed"), batch = read_int("batch"), images = read_int("train_images");
    if (seed != static_cast<int64_t>(o.seed) || batch != o.batch || images != static_cast<int64_t>(train.images.size()))
      throw std::runtime_error(fmt::format(
          "{}: made with seed {}, batch {}, {} training images; this run has seed {}, batch {}, {} images (the data "
          "order would change: resume with the same seed, batch and data)",
          path, seed, batch, images, o.seed, o.batch, train.images.size()));
    net->load(a);
    torch::serialize::InputArchive average_archive;
    const bool has_average = a.try_read("weight_average", average_archive);
    if (has_average != o.ema.enabled())
      throw std::runtime_error(
          has_average ? fmt::format("{}: made with a weight average (--ema-decay); resume with the same --ema-decay "
                                    "and --ema-ramp",
                                    path)
                      : fmt::format("{}: made without a weight average; resume without --ema-decay {} (or train anew "
                                    "in another folder)",
                                    path, o.ema.decay));
    if (has_average) {
      torch::Tensor decay, ramp;
      a.read("ema_decay", decay);
      a.read("ema_ramp", ramp);
      if (decay.item<double>() != o.ema.decay || ramp.item<double>() != o.ema.ramp)
        throw std::runtime_error(fmt::format(
            "{}: made with --ema-decay {} --ema-ramp {}; this run has {} and {} (resume with the same average)", path,
            decay.item<double>(), ramp.item<double>(), o.ema.decay, o.ema.ramp));
      average->load(average_archive);
      average->eval();
    }
    torch::serialize::InputArchive opt;
    a.read("optimizer", opt);
    optimizer->load(opt);
    iteration = read_int("iteration");
    torch::Tensor avg;
    a.read("loss_avg", avg);
    loss_avg = avg.item<double>();
  }

  /// Raw head outputs of one image -> boxes in network pixels, after NMS.
  std::vector<detector::Box> decode(const std::vector<torch::Tensor>& outs, int64_t image) const {
    std::vector<detector::Box> boxes;
    const std::vector<int>& heads = net->head_layers();
    for (size_t h = 0; h < heads.size(); ++h) {
      const detector::Layer& l = model.layers[static_cast<size_t>(heads[h])];
      const torch::Tensor t = outs[h][image].contiguous();
      detector::decode_head(t.data_ptr<float>(), l.input, l, model.net.width, model.net.height, kValPThresh, boxes);
    }
    detector::non_max_suppression(boxes, kValNms);
    return boxes;
  }
};

Trainer::Trainer(TrainOptions options) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.o = std::move(options);
  const std::vector<std::string> problems = s.o.validate();
  if (!problems.empty()) {
    std::string msg = "Trainer: invalid options:";
    for (const auto& p : problems) msg += "\n  " + p;
    throw std::invalid_argument(msg);
  }
  torch::set_num_threads(s.o.threads);
  s.cfg_text = read_file(s.o.cfg);
  s.model = detector::parse_darknet_cfg_string(s.cfg_text, s.o.cfg);
  if (s.model.heads().empty())
    throw detector::DarknetFormatError(fmt::format("{}: the network has no [region] or [yolo] head to train", s.o.cfg));
  if (s.model.net.channels != 3)
    throw detector::DarknetFormatError(
        fmt::format("{}: [net] channels = {}: the trainer feeds RGB images (3)", s.o.cfg, s.model.net.channels));
  s.stem = fs::path(s.o.cfg).stem().string();
  s.train = load_yolo_dataset(s.o.data, s.o.train_split);
  if (!s.o.val_split.empty()) s.val = load_yolo_dataset(s.o.data, s.o.val_split);  // bad labels: now, not at the end
  for (const auto& l : s.model.layers)
    if ((l.type == LayerType::kRegion || l.type == LayerType::kYolo) &&
        static_cast<int>(s.train.class_names.size()) > l.classes)
      throw DatasetError(fmt::format("{}: {} classes, but the network's [{}] head (line {} of {}) has classes = {}",
                                     s.o.data, s.train.class_names.size(), detector::layer_type_name(l.type),
                                     l.cfg_line, s.o.cfg, l.classes));

  torch::manual_seed(s.o.seed);
  s.net = DarknetNet(s.model);
  if (!s.o.init_weights.empty()) {
    detector::DarknetModel m = s.model;
    if (s.o.init_partial) {
      s.init_layers = detector::load_darknet_weights_prefix(m, s.o.init_weights);
      s.net->load_weights(m, s.init_layers);
    } else {
      detector::load_darknet_weights(m, s.o.init_weights);
      s.net->load_weights(m);
      s.init_layers = static_cast<int>(std::count_if(
          m.layers.begin(), m.layers.end(), [](const auto& l) { return l.type == LayerType::kConvolutional; }));
    }
  }
  if (s.o.ema.enabled()) {
    // Built after the network so that the network's seeded initialisation is the same with or without it.
    s.average = DarknetNet(s.model);
    copy_weights(*s.average, *s.net);
    s.average->eval();
  }
  std::vector<torch::optim::OptimizerParamGroup> groups;
  groups.emplace_back(s.net->kernel_parameters(),
                      std::make_unique<torch::optim::SGDOptions>(
                          torch::optim::SGDOptions(s.o.lr.base).momentum(s.o.momentum).weight_decay(s.o.decay)));
  groups.emplace_back(s.net->other_parameters(), std::make_unique<torch::optim::SGDOptions>(
                                                     torch::optim::SGDOptions(s.o.lr.base).momentum(s.o.momentum)));
  s.optimizer = std::make_unique<torch::optim::SGD>(std::move(groups),
                                                    torch::optim::SGDOptions(s.o.lr.base).momentum(s.o.momentum));
  std::error_code ec;
  fs::create_directories(s.o.out_dir, ec);
  if (!fs::is_directory(s.o.out_dir))
    throw std::runtime_error(fmt::format("{}: cannot create the output folder: {}", s.o.out_dir, ec.message()));
  if (s.o.resume) s.load_checkpoint();
}

Trainer::~Trainer() = default;

int64_t Trainer::iteration() const { return impl_->iteration; }
const TrainOptions& Trainer::options() const { return impl_->o; }
size_t Trainer::train_images() const { return impl_->train.images.size(); }
int Trainer::init_layers() const { return impl_->init_layers; }
void Trainer::save_weights(const std::string& path) const { impl_->save_weights(path, impl_->exported()); }

TrainSummary Trainer::run(const std::function<void(const TrainProgress&)>& progress, const std::atomic<bool>* stop) {
  Impl& s = *impl_;
  TrainSummary summary;
  summary.start_iteration = s.iteration;
  summary.max_batches = s.o.max_batches;
  summary.checkpoint = s.out(kCheckpointName);
  {
    std::ofstream cfg_copy(s.out(s.stem + ".cfg"), std::ios::binary);
    cfg_copy << s.cfg_text;
  }
  torch::set_num_threads(s.o.threads);
  const auto t0 = std::chrono::steady_clock::now();
  int64_t images = 0;
  double data_s = 0.0;
  std::vector<float> input;
  std::vector<std::vector<LabeledBox>> truths;
  const int per = s.o.batch / s.o.subdivisions;
  const std::vector<int>& heads = s.net->head_layers();
  bool first = true;
  while (s.iteration < s.o.max_batches) {
    s.net->train();
    s.optimizer->zero_grad();
    TrainProgress p;
    int64_t responsible = 0;
    double iou_sum = 0.0;
    for (int sub = 0; sub < s.o.subdivisions; ++sub) {
      const auto d0 = std::chrono::steady_clock::now();
      s.load_sub_batch(s.iteration, sub, input, truths);
      data_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - d0).count();
      for (const auto& t : truths) p.truths += static_cast<int64_t>(t.size());
      const torch::Tensor x =
          torch::from_blob(input.data(), {per, 3, s.model.net.height, s.model.net.width}, torch::kFloat32);
      const std::vector<torch::Tensor> outs = s.net->forward(x);
      torch::Tensor loss = torch::zeros({});
      for (size_t h = 0; h < heads.size(); ++h) {
        const detector::Layer& l = s.model.layers[static_cast<size_t>(heads[h])];
        const LossTerms terms = l.type == LayerType::kRegion
                                    ? region_loss(outs[h], l, truths)
                                    : yolo_loss(outs[h], l, s.model.net.width, s.model.net.height, truths);
        loss = loss + terms.total;
        p.coord += terms.coord;
        p.object += terms.object;
        p.noobject += terms.noobject;
        p.cls += terms.cls;
        responsible += terms.responsible;
        iou_sum += terms.iou_sum;
      }
      (loss / static_cast<double>(s.o.batch)).backward();
    }
    p.mean_iou = responsible > 0 ? iou_sum / static_cast<double>(responsible) : 0.0;
    p.coord /= s.o.batch, p.object /= s.o.batch, p.noobject /= s.o.batch, p.cls /= s.o.batch;
    p.loss = p.coord + p.object + p.noobject + p.cls;
    p.learning_rate = s.o.lr.at(s.iteration);
    for (auto& group : s.optimizer->param_groups())
      static_cast<torch::optim::SGDOptions&>(group.options()).lr(p.learning_rate);
    s.optimizer->step();
    ++s.iteration;
    if (s.average) update_weight_average(*s.average, *s.net, s.o.ema.decay_at(s.iteration));
    images += s.o.batch;
    s.loss_avg = s.loss_avg < 0 ? p.loss : 0.9 * s.loss_avg + 0.1 * p.loss;
    if (first) summary.first_loss = p.loss, first = false;

    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    p.iteration = s.iteration;
    p.max_batches = s.o.max_batches;
    p.loss_avg = s.loss_avg;
    p.elapsed_s = elapsed;
    p.images_per_s = elapsed > 0 ? images / elapsed : 0.0;
    p.data_share = elapsed > 0 ? data_s / elapsed : 0.0;
    p.eta_s = p.images_per_s > 0 ? (s.o.max_batches - s.iteration) * s.o.batch / p.images_per_s : 0.0;
    if (progress && (s.iteration % s.o.log_interval == 0 || s.iteration == s.o.max_batches)) progress(p);

    const bool stopping = stop && stop->load();
    if (s.iteration % s.o.checkpoint_interval == 0 || s.iteration == s.o.max_batches || stopping) {
      s.save_checkpoint();
      s.save_weights(s.out(s.stem + "_last.weights"), s.exported());
      summary.weights = s.out(s.stem + "_last.weights");
    }
    if (s.o.weights_interval > 0 && s.iteration % s.o.weights_interval == 0) {
      s.save_weights(s.out(fmt::format("{}_{}.weights", s.stem, s.iteration)), s.exported());
      if (s.average) s.save_weights(s.out(fmt::format("{}_raw_{}.weights", s.stem, s.iteration)), s.net);
    }
    if (stopping && s.iteration < s.o.max_batches) {
      summary.interrupted = true;
      break;
    }
  }
  summary.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  summary.images_per_s = summary.elapsed_s > 0 ? images / summary.elapsed_s : 0.0;
  summary.iteration = s.iteration;
  summary.loss_avg = s.loss_avg;
  if (!summary.interrupted) {
    summary.weights = s.out(s.stem + "_final.weights");
    s.save_weights(summary.weights, s.exported());
    if (s.average) {
      summary.raw_weights = s.out(s.stem + "_raw_final.weights");
      s.save_weights(summary.raw_weights, s.net);
    }
    if (!fs::is_regular_file(s.out(kCheckpointName))) s.save_checkpoint();
    if (!s.o.val_split.empty()) summary.validation = validate(s.o.val_split, s.o.val_max_images);
  }
  return summary;
}

DetectionMetrics Trainer::validate(const std::string& split, int max_images) const {
  Impl& s = *impl_;
  const YoloDataset val = split == s.o.val_split ? s.val : load_yolo_dataset(s.o.data, split);
  torch::NoGradGuard no_grad;
  DarknetNet net = s.exported();
  net->eval();
  const cv::Size net_size(s.model.net.width, s.model.net.height);
  std::vector<float> input(static_cast<size_t>(3) * net_size.area());
  std::vector<ImageDetections> results;
  for (size_t i : evenly_spaced(val.images.size(), static_cast<size_t>(std::max(0, max_images)))) {
    const DatasetImage& img = val.images[i];
    const cv::Mat bgr = cv::imread(img.image_path, cv::IMREAD_COLOR);
    if (bgr.empty()) throw DatasetError(fmt::format("{}: cannot read the image", img.image_path));
    const AugmentedImage a = augment_image(bgr, {}, net_size, AugmentOptions::none(), 0);
    bgr_to_chw(a.bgr, input.data());
    const torch::Tensor x = torch::from_blob(input.data(), {1, 3, net_size.height, net_size.width}, torch::kFloat32);
    const std::vector<torch::Tensor> outs = net->forward(x);
    ImageDetections d;
    d.name = img.image_path, d.width = bgr.cols, d.height = bgr.rows;
    const double sx = static_cast<double>(bgr.cols) / net_size.width,
                 sy = static_cast<double>(bgr.rows) / net_size.height;
    for (detector::Box b : s.decode(outs, 0)) {
      if (b.class_id != 0) continue;  // drones only, as the truths below (a multi-class model's distractors are not)
      b.cx = static_cast<float>(b.cx * sx), b.w = static_cast<float>(b.w * sx);
      b.cy = static_cast<float>(b.cy * sy), b.h = static_cast<float>(b.h * sy);
      d.predictions.push_back(b);
    }
    d.predictions = detector::clip_to_image(d.predictions, static_cast<float>(bgr.cols),
                                            static_cast<float>(bgr.rows));  // as val does
    for (const LabeledBox& t : img.boxes) {
      if (t.cls != 0) continue;
      detector::Box b;
      b.cx = t.cx * bgr.cols, b.cy = t.cy * bgr.rows, b.w = t.w * bgr.cols, b.h = t.h * bgr.rows;
      d.truths.push_back(b);
    }
    results.push_back(std::move(d));
  }
  if (!s.average) s.net->train();  // the average stays in eval mode
  return evaluate_detections(results, MetricsOptions{});
}

}  // namespace wingman::training
