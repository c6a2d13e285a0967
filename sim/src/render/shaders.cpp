// SPDX-License-Identifier: MIT
// GLSL ES 3.00 sources of the renderer's passes.
#include "shaders.hpp"

namespace wingman::sim::detail {

const char* const kDroneVertexShader = R"(precision highp float;
layout(location = 0) in vec3 a_position;  // body frame, metres
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_colour;    // linear RGB, opacity
layout(location = 3) in float a_part;     // 0 body, k propeller k - 1
uniform mat4 u_cam_from_part[17];         // optical frame from body (part 0) or from a turned propeller
uniform vec4 u_proj;                      // pinhole pixels: ndc x = u_proj.x X / Z + u_proj.y, y likewise (z, w)
uniform vec2 u_depth;                     // ndc z = u_depth.x + u_depth.y / Z
out vec3 v_p_cam;
out vec3 v_n_cam;
out vec4 v_colour;
void main() {
  mat4 m = u_cam_from_part[int(a_part + 0.5)];
  vec4 p = m * vec4(a_position, 1.0);
  v_p_cam = p.xyz;
  v_n_cam = mat3(m) * a_normal;
  v_colour = a_colour;
  gl_Position = vec4(u_proj.x * p.x + u_proj.y * p.z, u_proj.z * p.y + u_proj.w * p.z,
                     u_depth.x * p.z + u_depth.y, p.z);
}
)";

const char* const kDroneFragmentShader = R"(precision highp float;
precision highp int;
in vec3 v_p_cam;
in vec3 v_n_cam;
in vec4 v_colour;
uniform int u_flat;          // 1: unlit albedo
uniform vec3 u_sun_cam;      // unit vector to the sun, optical frame
uniform vec3 u_up_cam;       // world up, optical frame
uniform vec3 u_sun_rgb;      // direct sunlight, linear
uniform vec3 u_sky_rgb;      // sky light from above, linear
uniform vec3 u_ground_rgb;   // light bounced from the ground, linear
uniform uint u_id;
layout(location = 0) out vec4 o_colour;
layout(location = 1) out uint o_id;
void main() {
  vec3 c = v_colour.rgb;
  if (u_flat == 0) {
    vec3 n = normalize(v_n_cam);
    vec3 view = normalize(v_p_cam);
    if (dot(n, view) > 0.0) n = -n;  // double-sided
    vec3 ambient = mix(u_ground_rgb, u_sky_rgb, 0.5 + 0.5 * dot(n, u_up_cam));
    float ndl = max(dot(n, u_sun_cam), 0.0);
    vec3 h = normalize(u_sun_cam - view);
    float specular = ndl > 0.0 ? 0.12 * pow(max(dot(n, h), 0.0), 40.0) : 0.0;
    c = c * (ambient + u_sun_rgb * ndl) + u_sun_rgb * specular;
  }
  o_colour = vec4(c * v_colour.a, v_colour.a);
  o_id = u_id;
}
)";

const char* const kFullscreenVertexShader = R"(void main() {
  vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
)";

const char* const kBackgroundFragmentShader =
    R"(uniform sampler2D u_map;       // per pixel corner: layer pixel coordinates; x < -1e8 outside the view
uniform vec3 u_norm;           // normalized = u_norm.xy + layer pixel * u_norm.z
uniform ivec2 u_size;          // camera image size, pixels
uniform mat3 u_R_cam_to_world;
uniform vec3 u_cam_in_world;
// scene
uniform vec3 u_uniform_rgb;
uniform vec3 u_zenith_rgb;
uniform vec3 u_horizon_rgb;
uniform vec3 u_sun_dir;        // unit, world
uniform vec3 u_sun_glow_rgb;
uniform vec3 u_cloud_rgb;
uniform vec3 u_cloud;          // cover, altitude, scale
uniform vec3 u_ground_a_rgb;   // lit
uniform vec3 u_ground_b_rgb;
uniform float u_ground_scale;
uniform vec3 u_tree_rgb;       // lit
uniform vec3 u_tree;           // distance, height, depth of the forest belt
uniform float u_visibility;
uniform sampler2D u_noise;     // the scene seed's random values
uniform vec2 u_offset;         // the scene seed's offset into the noise
layout(location = 0) out vec4 o_colour;

// Value noise from a seeded 256 x 256 random texture (bilinear, repeating), with smoothstep interpolation; the
// texture lookup replaces four hashes (llvmpipe runs every branch of a shader, so cheap arithmetic matters).
float value_noise(vec2 p) {
  vec2 i = floor(p);
  vec2 f = p - i;
  return texture(u_noise, (i + f * f * (3.0 - 2.0 * f) + 0.5) * (1.0 / 256.0)).r;
}
// Fractal noise in [0, 1] with mean ~0.5; octaves finer than the footprint (in units of p) fade to their mean.
float fbm(vec2 p, int octaves, float footprint) {
  float sum = 0.0, amplitude = 0.5, frequency = 1.0, total = 0.0;
  for (int k = 0; k < 6; ++k) {
    if (k >= octaves) break;
    float keep = clamp(1.5 - footprint * frequency * 2.0, 0.0, 1.0);
    sum += amplitude * mix(0.5, value_noise(p * frequency + vec2(float(k) * 37.17, float(k) * 11.31)), keep);
    total += amplitude;
    amplitude *= 0.5;
    frequency *= 2.03;
  }
  return sum / total;
}

#if SCENE
vec3 sky(vec3 d, float pix) {
  float up = max(d.z, 0.0);
  vec3 c = mix(u_horizon_rgb, u_zenith_rgb, pow(up, 0.55));
  float cs = max(dot(d, u_sun_dir), 0.0);
  c += u_sun_glow_rgb * (0.25 * pow(cs, 8.0) + 0.6 * pow(cs, 200.0));
  c += u_sun_glow_rgb * 12.0 * smoothstep(0.99996 - pix, 0.99996 + pix, cs);  // the disc (0.5 degrees)
#if CLOUDS
  float rise = max(d.z, 0.005);
  float t = max(u_cloud.y - u_cam_in_world.z, 1.0) / rise;
  vec2 p = (u_cam_in_world.xy + t * d.xy) / u_cloud.z + u_offset;
  float n = fbm(p, 5, t * pix / (u_cloud.z * rise));
  float threshold = mix(0.8, 0.3, u_cloud.x);
  float density = smoothstep(threshold - 0.04, threshold + 0.12, n) * exp(-t / 40000.0) * step(0.005, d.z);
  vec3 cloud = u_cloud_rgb * (0.72 + 0.45 * smoothstep(threshold, threshold + 0.3, n));
  c = mix(c, cloud, density);
#endif
  return c;
}

// Radiance along the world-frame ray d from the camera; pix: the pixel's angular size, radians.
vec3 background(vec3 d, float pix) {
  float cam_z = max(u_cam_in_world.z, 0.05);
  vec3 c = sky(d, pix);
  float t_ground = d.z < 0.0 ? cam_z / -d.z : 1e30;
#if GROUND
  // The ground plane z = 0, hazed towards the horizon colour; soft over one pixel at the horizon.
  vec2 g = u_cam_in_world.xy + min(t_ground, 1e6) * d.xy;
  float footprint = min(t_ground, 1e6) * pix / max(-d.z, 0.01);
  float fields = fbm(g / u_ground_scale + u_offset, 4, footprint / u_ground_scale);
  float grass = fbm(g / 0.6 - u_offset, 5, footprint / 0.6);
  vec3 albedo = mix(u_ground_a_rgb, u_ground_b_rgb, smoothstep(0.44, 0.56, fields)) * (0.7 + 0.6 * grass);
  vec3 ground = mix(albedo, u_horizon_rgb, 1.0 - exp(-3.0 * min(t_ground, 1e6) / u_visibility));
  c = mix(c, ground, clamp(0.5 - d.z / pix, 0.0, 1.0));
#else
  t_ground = 1e30;
#endif
#if TREES
  // A belt of forest and hills around the camera, from u_tree.x to u_tree.x + u_tree.z away: its front face where a
  // ray meets it below the canopy, its canopy where a ray from above comes down onto it.
  float h = max(length(d.xy), 1e-4);
  vec2 around = d.xy / h;
  float t = u_tree.x / h;
  float z = cam_z + t * d.z;
  float crowns = fbm(around * (u_tree.x / 4.0) + u_offset, 3, t * pix / 4.0);
  float hills = fbm(around * 2.5 - u_offset, 2, 0.0);
  float gaps = smoothstep(0.3, 0.42, value_noise(around * 5.0 + u_offset.yx));
  float top = gaps * u_tree.y * (0.55 + 0.9 * crowns) + u_tree.y * 1.6 * hills * hills;
  float edge = max(t * pix, 1e-3);  // one pixel at the front face, metres
  float front = clamp((top - z) / edge + 0.5, 0.0, 1.0) * step(t, t_ground);
  float down = max(-d.z, 1e-4);
  float t_top = max(cam_z - top, 0.0) / down;  // where the ray reaches the canopy's height
  float r_top = t_top * h;
  float edge_top = max(t_top * pix / down, 1e-3);
  float canopy = step(top + 0.5, cam_z) * step(0.0, -d.z) *
                 clamp((r_top - u_tree.x) / edge_top + 0.5, 0.0, 1.0) *
                 clamp((u_tree.x + u_tree.z - r_top) / edge_top + 0.5, 0.0, 1.0);
  float cover = max(front, canopy);
  float t_trees = front >= canopy ? t : t_top;
  // Leaves on the front face (1.2 m), crowns on the canopy seen from above (5 m).
  float leaf_scale = front >= canopy ? 1.2 : 5.0;
  vec2 leaf_at = front >= canopy ? around * (u_tree.x / 1.2) + vec2(0.8 * z, -0.6 * z) / 1.2
                                 : (u_cam_in_world.xy + t_top * d.xy) / 5.0;
  float leaves = fbm(leaf_at, 3, t_trees * pix / leaf_scale);
  vec3 tree = mix(u_tree_rgb * (0.55 + 0.9 * leaves), u_horizon_rgb, 1.0 - exp(-3.0 * t_trees / u_visibility));
  c = mix(c, tree, cover);
#endif
  return c;
}
#else
vec3 background(vec3 d, float pix) { return u_uniform_rgb; }
#endif

void main() {
  // This output pixel stands for the BG x BG block of camera pixels from BG * px.
  ivec2 px = ivec2(gl_FragCoord.xy);
  ivec2 c0 = min(px * BG, u_size);
  ivec2 c1 = min(px * BG + BG, u_size);
  vec2 m00 = texelFetch(u_map, c0, 0).xy;
  vec2 m10 = texelFetch(u_map, ivec2(c1.x, c0.y), 0).xy;
  vec2 m01 = texelFetch(u_map, ivec2(c0.x, c1.y), 0).xy;
  vec2 m11 = texelFetch(u_map, c1, 0).xy;
  // The mean of the block's corners in the field of view (blocks at its edge are partly outside).
  float valid = 0.0;
  vec2 sum = vec2(0.0);
  if (m00.x >= -1e8) { sum += m00; valid += 1.0; }
  if (m10.x >= -1e8) { sum += m10; valid += 1.0; }
  if (m01.x >= -1e8) { sum += m01; valid += 1.0; }
  if (m11.x >= -1e8) { sum += m11; valid += 1.0; }
  vec2 centre = sum / max(valid, 1.0);
  vec2 n = u_norm.xy + centre * u_norm.z;
  // The block's angular size, radians: what the sample stands for (finer detail is averaged away).
  float pix = (m00.x >= -1e8 && m10.x >= -1e8 ? length(m10 - m00) * u_norm.z : 1e-3 * float(BG)) / (1.0 + dot(n, n));
  o_colour = vec4(background(u_R_cam_to_world * normalize(vec3(n, 1.0)), pix), 1.0);
}
)";

const char* const kComposeFragmentShader = R"(uniform sampler2D u_layer;  // the drone layer, premultiplied linear RGBA
uniform vec4 u_rect;        // where the layer was drawn this time, layer pixels (x0, y0, x1, y1)
uniform vec2 u_layer_size;
uniform sampler2D u_bg;     // the background pass (one texel per BG x BG camera pixels)
uniform vec2 u_bg_scale;    // 1 / (BG * background texture size)
uniform float u_weight;     // 1 / motion-blur samples (FINAL 0: accumulated, then the sensor pass)
layout(location = 0) out vec4 o_colour;

vec4 layer_at(vec2 m) {
  if (m.x < u_rect.x || m.y < u_rect.y || m.x > u_rect.z || m.y > u_rect.w) return vec4(0.0);
  return texture(u_layer, m / u_layer_size);
}

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec2 centre = centre_of(px);
  bool in_view = centre.x >= -1e8;
  vec3 bg = in_view ? texture(u_bg, gl_FragCoord.xy * u_bg_scale).rgb : vec3(0.0);
#if LAYER
  Corners k = corners(px);
  // The drone layer's mean over SS x SS points of the pixel (premultiplied: composited over bg below).
  vec4 drones = vec4(0.0);
  const float inv = 1.0 / float(SS);
  for (int j = 0; j < SS; ++j) {
    for (int i = 0; i < SS; ++i) {
      vec2 f = (vec2(float(i), float(j)) + 0.5) * inv;
      drones += layer_at(mix(mix(k.m00, k.m10, f.x), mix(k.m01, k.m11, f.x), f.y));
    }
  }
  drones *= inv * inv;
  if (!in_view) drones = vec4(0.0);
#if FINAL
  o_colour = sensor(drones.rgb + (1.0 - drones.a) * bg, px, centre, in_view);
#else
  o_colour = vec4((drones.rgb - drones.a * bg) * u_weight, 0.0);  // added to the LAYER 0 pass's weight * bg
#endif
#else
#if FINAL
  o_colour = sensor(bg, px, centre, false);
#else
  o_colour = vec4(bg * u_weight, u_weight);
#endif
#endif
}
)";

const char* const kFragmentPreamble = R"(precision highp float;
precision highp int;
precision highp sampler2D;
precision highp usampler2D;
)";

const char* const kSensorFunctions = R"(
// ---- sensor: exposure gain, sRGB, noise, 8-bit quantisation; the drone id at the pixel centre ----
uniform highp usampler2D u_ids;  // drone id per layer pixel
uniform vec4 u_id_rect;          // where the id layer is valid this frame, layer pixels
uniform float u_gain;
uniform float u_noise_std;       // 8-bit levels
uniform float u_shot;            // variance per level
uniform uvec2 u_frame_seed;

uint pcg(uint v) {
  uint state = v * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}
// A zero-mean, unit-variance number from the four bytes of a hash (Irwin-Hall: nearly Gaussian, within 3.5 sigma).
float gaussian(uint h) {
  float sum = float(h & 255u) + float((h >> 8) & 255u) + float((h >> 16) & 255u) + float(h >> 24);
  return (sum * (1.0 / 255.0) - 2.0) * 1.7320508;
}
float srgb(float c) {
  c = clamp(c, 0.0, 1.0);
  return c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}
// The 8-bit pixel (in 0..1) and, in alpha, the id of the drone seen at the pixel centre (layer pixel `centre`).
vec4 sensor(vec3 linear, ivec2 px, vec2 centre, bool in_view) {
  vec3 c = linear * u_gain;
  vec3 v = vec3(srgb(c.r), srgb(c.g), srgb(c.b)) * 255.0;
#if NOISE
  uint h = pcg(uint(px.x) ^ pcg(uint(px.y) ^ pcg(u_frame_seed.x ^ pcg(u_frame_seed.y))));
  v += sqrt(u_noise_std * u_noise_std + u_shot * v) *
       vec3(gaussian(pcg(h)), gaussian(pcg(h + 1u)), gaussian(pcg(h + 2u)));
#endif
  v = clamp(floor(v + 0.5), 0.0, 255.0);
  uint id = 0u;
  if (in_view && centre.x >= u_id_rect.x && centre.y >= u_id_rect.y && centre.x < u_id_rect.z &&
      centre.y < u_id_rect.w) {
    id = texelFetch(u_ids, ivec2(floor(centre)), 0).r;
  }
  return vec4(v / 255.0, float(id) / 255.0);
}
)";

const char* const kLensFunctions = R"(
// ---- the lens map: per camera pixel corner, coordinates in the drone layer (x < -1e8: outside the view) ----
uniform sampler2D u_map;
uniform sampler2D u_centres;  // per camera pixel: its centre in layer pixels; x < -1e8 outside the view
struct Corners {
  vec2 m00, m10, m01, m11;
  bool in_view;
};
Corners corners(ivec2 px) {
  Corners c;
  c.m00 = texelFetch(u_map, px, 0).xy;
  c.m10 = texelFetch(u_map, px + ivec2(1, 0), 0).xy;
  c.m01 = texelFetch(u_map, px + ivec2(0, 1), 0).xy;
  c.m11 = texelFetch(u_map, px + ivec2(1, 1), 0).xy;
  c.in_view = min(min(c.m00.x, c.m10.x), min(c.m01.x, c.m11.x)) >= -1e8;
  return c;
}
// One fetch where the corners are not needed.
vec2 centre_of(ivec2 px) { return texelFetch(u_centres, px, 0).xy; }
)";

const char* const kFinalFragmentShader = R"(uniform sampler2D u_accum;  // linear RGB, the motion-blur samples' mean
layout(location = 0) out vec4 o_colour;
void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec2 centre = centre_of(px);
  o_colour = sensor(texelFetch(u_accum, px, 0).rgb, px, centre, centre.x >= -1e8);
}
)";

}  // namespace wingman::sim::detail
