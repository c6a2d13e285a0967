// SPDX-License-Identifier: MIT
// BusWatch: status heartbeats and channel counts from the LCM bus, for launchers.
#include "wingman/launcher/bus_watch.hpp"

#include <fmt/format.h>
#include <wingman/common/message_validation.hpp>

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace wingman::launcher {

BusWatch::BusWatch(const std::string& lcm_url, const std::string& count_channels)
    : owned_lcm_(std::make_unique<lcm::LCM>(lcm_url)), lcm_(owned_lcm_.get()) {
  if (!lcm_->good()) throw std::runtime_error(fmt::format("cannot open the LCM bus '{}'", lcm_url));
  subscribe(count_channels);
}

BusWatch::BusWatch(lcm::LCM& lcm, const std::string& count_channels) : lcm_(&lcm) { subscribe(count_channels); }

BusWatch::~BusWatch() {
  for (lcm::Subscription* s : subscriptions_) lcm_->unsubscribe(s);
}

void BusWatch::subscribe(const std::string& count_channels) {
  subscriptions_.push_back(lcm_->subscribe("STATUS_.*", &BusWatch::on_status, this));
  if (!count_channels.empty()) subscriptions_.push_back(lcm_->subscribe(count_channels, &BusWatch::on_counted, this));
}

void BusWatch::on_status(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
  status_t s;
  if (s.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) < 0 || !common::validate_message(s).empty()) {
    ++bad_messages_;
    return;
  }
  statuses_[s.process] = std::move(s);
}

void BusWatch::on_counted(const lcm::ReceiveBuffer* /*rbuf*/, const std::string& channel) { ++counts_[channel]; }

void BusWatch::spin(int timeout_ms) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(std::max(timeout_ms, 0));
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (lcm_->handleTimeout(static_cast<int>(std::max<int64_t>(left, 0))) <= 0) return;  // timeout or error
    if (left <= 0) return;
  }
}

bool BusWatch::spin_until(const std::function<bool()>& done, double timeout_s, const std::function<bool()>& stop) {
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                             std::chrono::duration<double>(std::max(timeout_s, 0.0)));
  for (;;) {
    if (done()) return true;
    if ((stop && stop()) || std::chrono::steady_clock::now() >= deadline) return false;
    spin(50);
  }
}

std::vector<std::string> BusWatch::wait_for_status(const std::vector<std::string>& names, double timeout_s,
                                                   const std::function<bool()>& stop) {
  auto missing = [&] {
    std::vector<std::string> m;
    for (const auto& n : names) {
      if (!statuses_.count(n)) m.push_back(n);
    }
    return m;
  };
  spin_until([&] { return missing().empty(); }, timeout_s, stop);
  return missing();
}

const status_t* BusWatch::status(const std::string& name) const {
  const auto it = statuses_.find(name);
  return it == statuses_.end() ? nullptr : &it->second;
}

int64_t BusWatch::count(const std::string& channel) const {
  const auto it = counts_.find(channel);
  return it == counts_.end() ? 0 : it->second;
}

int64_t channel_count(const status_t& status, const std::string& channel, int8_t direction) {
  for (const auto& c : status.channels) {
    if (c.channel == channel && c.direction == direction) return c.count;
  }
  return 0;
}

}  // namespace wingman::launcher
