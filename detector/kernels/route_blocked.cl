// SPDX-License-Identifier: MIT
// Darknet [route]: copies the channels of one input into the output at a channel offset (the host runs
// it once per routed layer), both in the 16-channel blocked layout.
// One work-item: one row of one channel of one image.
__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void route_copy_blocked(
    __global const float* restrict in, __global float* restrict out, const int in_c, const int in_cb,
    const int out_cb, const int channel_offset, const int h, const int w, const int hp, const int wp,
    const int border) {
  const int y = get_global_id(0);
  const int nc = get_global_id(1);  // n * in_c + c
  const int n = nc / in_c;
  const int c = nc - n * in_c;
  const int oc = c + channel_offset;
  __global const float* src =
      in + (((size_t)(n * in_cb + c / 16) * hp + y + border) * wp + border) * 16 + (c % 16);
  __global float* dst = out + (((size_t)(n * out_cb + oc / 16) * hp + y + border) * wp + border) * 16 + (oc % 16);
  for (int x = 0; x < w; ++x) dst[x * 16] = src[x * 16];
}

// The same copy when the input's channels fill whole blocks and land on a block boundary of the output
// (channel_offset and in_c multiples of 16, the usual case): whole 16-channel pixels, one vector each.
// One work-item: one row of one channel block of one image.
__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void route_copy_blocks(
    __global const float* restrict in, __global float* restrict out, const int in_blocks, const int in_cb,
    const int out_cb, const int block_offset, const int h, const int w, const int hp, const int wp,
    const int border) {
  const int y = get_global_id(0);
  const int nb = get_global_id(1);  // n * in_blocks + b
  const int n = nb / in_blocks;
  const int b = nb - n * in_blocks;
  __global const float* src = in + (((size_t)(n * in_cb + b) * hp + y + border) * wp + border) * 16;
  __global float* dst = out + (((size_t)(n * out_cb + b + block_offset) * hp + y + border) * wp + border) * 16;
  for (int x = 0; x < w; ++x) vstore16(vload16(x, src), x, dst);
}
