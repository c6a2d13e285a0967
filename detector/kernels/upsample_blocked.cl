// SPDX-License-Identifier: MIT
// Nearest-neighbour upsampling by an integer factor on the 16-channel blocked layout.
// One work-item: one output row of one channel block of one image.
__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void upsample_blocked(
    __global const float* restrict in, __global float* restrict out, const int in_hp, const int in_wp,
    const int in_border, const int out_w, const int out_hp, const int out_wp, const int out_border,
    const int factor) {
  const int y = get_global_id(0);
  const int nc = get_global_id(1);
  __global const float* in_row =
      in + ((size_t)nc * in_hp + y / factor + in_border) * in_wp * 16 + in_border * 16;
  __global float* out_row = out + ((size_t)nc * out_hp + y + out_border) * out_wp * 16 + out_border * 16;
  for (int x = 0; x < out_w; ++x) vstore16(vload16(x / factor, in_row), x, out_row);
}
