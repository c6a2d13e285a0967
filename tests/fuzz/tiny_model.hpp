// SPDX-License-Identifier: MIT
// A tiny Darknet network for the weights fuzz target and its seeds: 16x16x3 in, a 3x3 batch-normalized
// convolution, a max-pool, a 1x1 convolution and one [yolo] head (3 anchors, 1 class): 214 float32 values.
#pragma once

namespace wingman::fuzz {

inline const char* tiny_cfg() {
  return R"([net]
width=16
height=16
channels=3

[convolutional]
batch_normalize=1
filters=4
size=3
stride=1
pad=1
activation=leaky

[maxpool]
size=2
stride=2

[convolutional]
filters=18
size=1
stride=1
pad=1
activation=linear

[yolo]
mask=0,1,2
anchors=2,3, 4,5, 6,7
classes=1
num=3
)";
}

}  // namespace wingman::fuzz
