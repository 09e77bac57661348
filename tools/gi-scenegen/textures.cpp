// Procedural brick, wood, tartan and wire-mesh textures (textures.h). Colours are chosen in
// linear RGB and encoded to sRGB at the end; the patterns are periodic over the image so
// the textures tile.
#include "textures.h"

#include <algorithm>
#include <array>
#include <string>

namespace scenegen {
namespace {

// ---- sRGB without libm: x^2.4 = x^2 * x^0.4, and y = x^0.4 solves y^5 = x^2 (Newton).

double pow_0_4(double x) {
  if (x <= 0.0) return 0.0;
  const double a = x * x;
  double y = 1.0;  // y^5 - a is convex for y > 0: Newton from above decreases monotonically
  for (int i = 0; i < 64; ++i) y = (4.0 * y + a / (y * y * y * y)) / 5.0;
  return y;
}

const std::array<float, 256>& srgb_table() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int c = 0; c < 256; ++c) {
      const double s = c / 255.0;
      // x^2.4 = x^2 * x^0.4
      const double base = (s + 0.055) / 1.055;
      t[static_cast<std::size_t>(c)] = static_cast<float>(s <= 0.04045 ? s / 12.92 : base * base * pow_0_4(base));
    }
    return t;
  }();
  return table;
}

// ---- Deterministic noise, periodic over the image.

std::uint32_t hash(std::uint32_t x, std::uint32_t y, std::uint32_t seed) {
  std::uint32_t h = x * 0x8da6b343u ^ y * 0xd8163841u ^ seed * 0xcb1ab31fu;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return h;
}

float hash01(std::uint32_t x, std::uint32_t y, std::uint32_t seed) {
  return static_cast<float>(hash(x, y, seed) >> 8) / 16777216.0f;
}

int wrap(int i, int n) { return ((i % n) + n) % n; }

float smooth(float t) { return t * t * (3.0f - 2.0f * t); }

/// Value noise in [0, 1] on a lattice of `cells_x` x `cells_y` cells over the unit square,
/// periodic in both directions; (u, v) in cells of the lattice.
float value_noise(float u, float v, int cells_x, int cells_y, std::uint32_t seed) {
  const int i = static_cast<int>(u >= 0.0f ? u : u - 1.0f);
  const int j = static_cast<int>(v >= 0.0f ? v : v - 1.0f);
  const float fu = smooth(u - static_cast<float>(i)), fv = smooth(v - static_cast<float>(j));
  auto at = [&](int a, int b) {
    return hash01(static_cast<std::uint32_t>(wrap(a, cells_x)), static_cast<std::uint32_t>(wrap(b, cells_y)), seed);
  };
  const float top = at(i, j) + (at(i + 1, j) - at(i, j)) * fu;
  const float bottom = at(i, j + 1) + (at(i + 1, j + 1) - at(i, j + 1)) * fu;
  return top + (bottom - top) * fv;
}

/// Three octaves of value_noise at pixel (x, y) of a size x size image, the coarsest with
/// `cells` lattice cells across; result in [0, 1].
float fbm(float x, float y, int size, int cells, std::uint32_t seed) {
  float sum = 0.0f, amplitude = 0.5f, norm = 0.0f;
  for (int o = 0; o < 3; ++o) {
    const float scale = static_cast<float>(cells << o) / static_cast<float>(size);
    sum += amplitude * value_noise(x * scale, y * scale, cells << o, cells << o, seed + static_cast<std::uint32_t>(o));
    norm += amplitude;
    amplitude *= 0.5f;
  }
  return sum / norm;
}

glm::vec3 mix(glm::vec3 a, glm::vec3 b, float t) { return a + (b - a) * t; }

/// The image from a function of the texel giving linear RGB and alpha (0..1).
template <class F>
engine::Image make_image(std::string name, int size, F&& texel) {
  engine::Image img;
  img.name = std::move(name);
  img.width = size;
  img.height = size;
  img.rgba8.reserve(static_cast<std::size_t>(size) * static_cast<std::size_t>(size) * 4);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const glm::vec4 c = texel(x, y);
      img.rgba8.push_back(linear_to_srgb8(c.x));
      img.rgba8.push_back(linear_to_srgb8(c.y));
      img.rgba8.push_back(linear_to_srgb8(c.z));
      img.rgba8.push_back(static_cast<std::uint8_t>(std::clamp(c.w, 0.0f, 1.0f) * 255.0f + 0.5f));
    }
  return img;
}

}  // namespace

float srgb8_to_linear(std::uint8_t c) { return srgb_table()[c]; }

std::uint8_t linear_to_srgb8(float v) {
  const std::array<float, 256>& t = srgb_table();
  v = std::clamp(v, 0.0f, 1.0f);
  // The first code whose value is >= v, or the one below it when that is nearer.
  const auto it = std::lower_bound(t.begin(), t.end(), v);
  if (it == t.end()) return 255;
  if (it == t.begin()) return 0;
  const auto hi = static_cast<int>(it - t.begin());
  return static_cast<std::uint8_t>(v - *(it - 1) <= *it - v ? hi - 1 : hi);
}

glm::vec3 mean_linear_rgb(const engine::Image& image, std::uint8_t min_alpha) {
  glm::dvec3 sum(0.0);
  std::size_t n = 0;
  for (std::size_t i = 0; i + 3 < image.rgba8.size(); i += 4) {
    if (image.rgba8[i + 3] < min_alpha) continue;
    sum += glm::dvec3(srgb8_to_linear(image.rgba8[i]), srgb8_to_linear(image.rgba8[i + 1]),
                      srgb8_to_linear(image.rgba8[i + 2]));
    ++n;
  }
  return n == 0 ? glm::vec3(0.0f) : glm::vec3(sum / static_cast<double>(n));
}

float transparent_fraction(const engine::Image& image, float cutoff) {
  std::size_t cut = 0, n = 0;
  for (std::size_t i = 3; i < image.rgba8.size(); i += 4, ++n)
    if (static_cast<float>(image.rgba8[i]) < cutoff * 255.0f) ++cut;
  return n == 0 ? 0.0f : static_cast<float>(cut) / static_cast<float>(n);
}

engine::Image brick_texture() {
  constexpr int kSize = 256, kCourse = 16, kBrick = 64, kJoint = 2;
  constexpr std::uint32_t kSeed = 1033;
  const glm::vec3 red(0.40f, 0.065f, 0.035f), orange(0.56f, 0.19f, 0.075f), mortar(0.40f, 0.38f, 0.34f);
  return make_image("brick", kSize, [&](int x, int y) {
    const int course = y / kCourse;
    const int shifted = x + (course % 2) * (kBrick / 2);  // running bond: every other course half a brick on
    const int brick = (shifted / kBrick) % (kSize / kBrick);
    const int lx = shifted % kBrick, ly = y % kCourse;
    const float fx = static_cast<float>(x), fy = static_cast<float>(y);
    const float grit = fbm(fx, fy, kSize, 16, kSeed);  // fine texture, same lattice everywhere: tiles
    if (lx < kJoint || ly < kJoint) {
      const float m = 0.85f + 0.3f * grit;
      return glm::vec4(mortar * m, 1.0f);
    }
    // Each brick its own shade between red and orange, a darker fired face and grit.
    const auto b = static_cast<std::uint32_t>(brick), c = static_cast<std::uint32_t>(course);
    const float tone = hash01(b, c, kSeed);
    const float shade = 0.82f + 0.3f * hash01(b, c, kSeed + 1);
    const float blotch = fbm(fx, fy, kSize, 8, kSeed + 7);
    glm::vec3 col = mix(red, orange, tone) * shade * (0.8f + 0.4f * grit) * (0.85f + 0.3f * blotch);
    // The arris (the brick's edge next to the joint) is a little darker.
    if (lx == kJoint || ly == kJoint || lx == kBrick - 1 || ly == kCourse - 1) col *= 0.8f;
    return glm::vec4(col, 1.0f);
  });
}

engine::Image wood_planks_texture() {
  constexpr int kSize = 256, kPlank = 64;
  constexpr std::uint32_t kSeed = 2718;
  const glm::vec3 early(0.50f, 0.31f, 0.155f), late(0.29f, 0.155f, 0.07f);
  return make_image("wood_planks", kSize, [&](int x, int y) {
    const int plank = y / kPlank;
    const int ly = y % kPlank;
    const auto p = static_cast<std::uint32_t>(plank);
    // Two boards per plank row: butt joints at j1 and j2 (the second board wraps around).
    const int j1 = static_cast<int>(hash01(p, 0, kSeed) * kSize);
    const int j2 = (j1 + 96 + static_cast<int>(hash01(p, 1, kSeed) * 64.0f)) % kSize;
    const bool board_a = j1 < j2 ? (x >= j1 && x < j2) : (x >= j1 || x < j2);
    const std::uint32_t board = p * 2 + (board_a ? 0u : 1u);
    const float fx = static_cast<float>(x), fy = static_cast<float>(ly);
    // Grain: rings across the plank, bent by noise that is periodic along u.
    const float bend = 10.0f * value_noise(fx * 4.0f / kSize, fy / 32.0f, 4, 2, kSeed + board) +
                       2.5f * value_noise(fx * 16.0f / kSize, fy / 8.0f, 16, 8, kSeed + 100 + board);
    const float spacing = 5.0f + 3.0f * hash01(board, 2, kSeed);
    const float ring = (fy + bend) / spacing;
    const float t = ring - static_cast<float>(static_cast<int>(ring));  // in [0, 1)
    const float late_wood =
        smooth(std::clamp((t - 0.55f) / 0.3f, 0.0f, 1.0f)) * (1.0f - smooth(std::clamp((t - 0.9f) / 0.1f, 0.0f, 1.0f)));
    glm::vec3 col = mix(early, late, 0.75f * late_wood);
    col *= 0.85f + 0.3f * hash01(board, 3, kSeed);                                       // board to board
    col *= 0.9f + 0.2f * value_noise(fx * 32.0f / kSize, fy / 2.0f, 32, 32, kSeed + 9);  // fibres
    // A knot on some boards: a dark ellipse.
    if (hash01(board, 4, kSeed) < 0.5f) {
      const float kx = hash01(board, 5, kSeed) * kSize, ky = 16.0f + hash01(board, 6, kSeed) * 32.0f;
      float dx = fx - kx;  // periodic along u
      if (dx > kSize / 2) dx -= kSize;
      if (dx < -kSize / 2) dx += kSize;
      const float d2 = (dx * dx) / 36.0f + (fy - ky) * (fy - ky) / 9.0f;
      if (d2 < 1.0f) col = mix(col, late * 0.6f, 1.0f - d2);
    }
    // Joints: the gap between plank rows and the butt joints, darker.
    if (ly == 0 || x == j1 || x == j2) col *= 0.35f;
    return glm::vec4(col, 1.0f);
  });
}

engine::Image tartan_fabric_texture() {
  constexpr int kSize = 128, kThread = 4, kThreads = kSize / kThread;  // 32 threads each way
  constexpr std::uint32_t kSeed = 4242;
  const glm::vec3 navy(0.07f, 0.10f, 0.34f), green(0.07f, 0.30f, 0.12f), cream(0.78f, 0.70f, 0.50f),
      red(0.62f, 0.06f, 0.04f);
  // The sett, the same for warp and weft: 6 navy, 2 cream, 6 navy, 8 green, 2 red, 8 green.
  auto stripe = [&](int thread) -> glm::vec3 {
    const int t = thread % kThreads;
    if (t < 6) return navy;
    if (t < 8) return cream;
    if (t < 14) return navy;
    if (t < 22) return green;
    if (t < 24) return red;
    return green;
  };
  return make_image("tartan_fabric", kSize, [&](int x, int y) {
    const int warp = x / kThread, weft = y / kThread;
    // 2/2 twill: the warp thread lies on top at two of every four crossings, shifting by
    // one per row (the diagonal rib of a twill).
    const bool warp_on_top = (warp + weft) % 4 < 2;
    // Across a thread its round profile: brighter in the middle.
    const int across = warp_on_top ? x % kThread : y % kThread;
    const float c = (static_cast<float>(across) + 0.5f) / kThread * 2.0f - 1.0f;
    const float profile = 0.72f + 0.28f * (1.0f - c * c);
    const float fuzz = 0.9f + 0.2f * hash01(static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), kSeed);
    const glm::vec3 col = (warp_on_top ? stripe(warp) : stripe(weft)) * profile * fuzz;
    return glm::vec4(col, 1.0f);
  });
}

engine::Image wire_mesh_texture() {
  constexpr int kSize = 256, kPitch = 16, kSamples = 4;  // 16 diamonds per metre; 4 x 4 coverage samples
  constexpr float kHalfWidth = 1.8f;                     // px, measured across the wire
  const glm::vec3 steel(0.42f, 0.43f, 0.44f);
  // Index of the nearest line x + s*y = k * pitch, and the distance to it across the wire (px).
  auto nearest_line = [](float x, float y, float s) {
    const float k = (x + s * y) / kPitch;
    return static_cast<int>(k >= 0.0f ? k + 0.5f : k - 0.5f);
  };
  auto distance = [&](float x, float y, float s) {
    const float f = (x + s * y) / kPitch - static_cast<float>(nearest_line(x, y, s));
    return (f < 0.0f ? -f : f) * kPitch * 0.70710678f;
  };
  return make_image("wire_mesh", kSize, [&](int x, int y) {
    float coverage = 0.0f;
    for (int sy = 0; sy < kSamples; ++sy)
      for (int sx = 0; sx < kSamples; ++sx) {
        const float px = static_cast<float>(x) + (static_cast<float>(sx) + 0.5f) / kSamples;
        const float py = static_cast<float>(y) + (static_cast<float>(sy) + 0.5f) / kSamples;
        if (distance(px, py, 1.0f) < kHalfWidth || distance(px, py, -1.0f) < kHalfWidth) coverage += 1.0f;
      }
    coverage /= kSamples * kSamples;
    const float cx = static_cast<float>(x) + 0.5f, cy = static_cast<float>(y) + 0.5f;
    const float d1 = distance(cx, cy, 1.0f), d2 = distance(cx, cy, -1.0f);
    // The nearer wire is the one seen; at a crossing the one passing under is shaded. Which
    // family is on top alternates from crossing to crossing, as the wires are woven.
    const bool first = d1 <= d2;
    const float d = first ? d1 : d2;
    const int crossing_index = nearest_line(cx, cy, 1.0f) + nearest_line(cx, cy, -1.0f);  // +-16 per tile: tiles
    const bool on_top = (crossing_index % 2 == 0) == first;
    const bool crossing = d1 < kHalfWidth && d2 < kHalfWidth;
    const float across = std::min(d / kHalfWidth, 1.0f);
    float light = 0.7f + 0.45f * (1.0f - across * across);  // round wire: a highlight along its middle
    if (crossing && !on_top) light *= 0.55f;
    return glm::vec4(coverage > 0.0f ? steel * light : steel, coverage);
  });
}

}  // namespace scenegen
