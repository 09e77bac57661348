#include "raytrace/material_textures.h"

#include <engine/check.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace gi {
namespace {

// 256 decoded values, built once.
const std::array<float, 256>& srgb_table() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) {
      const double c = i / 255.0;
      t[static_cast<std::size_t>(i)] =
          static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
    return t;
  }();
  return table;
}

// Bilinear lookup in one level (texel centres at half-integers, as GL samples).
glm::vec4 bilinear(const TextureMips::Level& l, const engine::TextureSampler& s, glm::vec2 uv) {
  // Far-away UVs: keep the float arithmetic exact by wrapping the integer part first.
  const float fx = uv.x * static_cast<float>(l.width) - 0.5f;
  const float fy = uv.y * static_cast<float>(l.height) - 0.5f;
  if (!std::isfinite(fx) || !std::isfinite(fy)) return l.texels[0];
  const float x0f = std::floor(fx), y0f = std::floor(fy);
  const float ax = fx - x0f, ay = fy - y0f;
  const auto clamp_int = [](float f) { return static_cast<int>(std::clamp(f, -1.0e9f, 1.0e9f)); };
  const int x0 = clamp_int(x0f), y0 = clamp_int(y0f);
  const int xa = wrap_texel(x0, l.width, s.wrap_s), xb = wrap_texel(x0 + 1, l.width, s.wrap_s);
  const int ya = wrap_texel(y0, l.height, s.wrap_t), yb = wrap_texel(y0 + 1, l.height, s.wrap_t);
  const auto at = [&](int x, int y) {
    return l.texels[static_cast<std::size_t>(y) * static_cast<std::size_t>(l.width) + static_cast<std::size_t>(x)];
  };
  return (1.0f - ay) * ((1.0f - ax) * at(xa, ya) + ax * at(xb, ya)) + ay * ((1.0f - ax) * at(xa, yb) + ax * at(xb, yb));
}

// Level k+1 from level k: each texel the overlap-weighted mean of the level-k texels its box
// covers (build_texture_mips).
TextureMips::Level half(const TextureMips::Level& src) {
  TextureMips::Level dst;
  dst.width = std::max(1, src.width / 2);
  dst.height = std::max(1, src.height / 2);
  dst.texels.resize(static_cast<std::size_t>(dst.width) * static_cast<std::size_t>(dst.height));
  // Box of destination texel d along an axis of n source texels: [d n / m, (d + 1) n / m).
  const auto taps = [](int d, int n, int m, std::array<std::pair<int, float>, 3>& out) {
    if (n == m) {
      out[0] = {d, 1.0f};
      return 1;
    }
    if (n % 2 == 0) {
      out[0] = {2 * d, 0.5f};
      out[1] = {2 * d + 1, 0.5f};
      return 2;
    }
    const float scale = static_cast<float>(m) / static_cast<float>(n);  // weight per full source texel
    const float lo = static_cast<float>(d) * static_cast<float>(n) / static_cast<float>(m);
    const float hi = static_cast<float>(d + 1) * static_cast<float>(n) / static_cast<float>(m);
    int count = 0;
    for (int i = static_cast<int>(std::floor(lo)); i < static_cast<int>(std::ceil(hi)) && count < 3; ++i) {
      const float w = std::min(hi, static_cast<float>(i + 1)) - std::max(lo, static_cast<float>(i));
      if (w > 0.0f) out[static_cast<std::size_t>(count++)] = {std::min(i, n - 1), w * scale};
    }
    return count;
  };
  std::array<std::pair<int, float>, 3> tx{}, ty{};
  for (int y = 0; y < dst.height; ++y) {
    const int ny = taps(y, src.height, dst.height, ty);
    for (int x = 0; x < dst.width; ++x) {
      const int nx = taps(x, src.width, dst.width, tx);
      glm::vec4 sum(0.0f);
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i)
          sum += tx[static_cast<std::size_t>(i)].second * ty[static_cast<std::size_t>(j)].second *
                 src.texels[static_cast<std::size_t>(ty[static_cast<std::size_t>(j)].first) *
                                static_cast<std::size_t>(src.width) +
                            static_cast<std::size_t>(tx[static_cast<std::size_t>(i)].first)];
      dst.texels[static_cast<std::size_t>(y) * static_cast<std::size_t>(dst.width) + static_cast<std::size_t>(x)] = sum;
    }
  }
  return dst;
}

}  // namespace

int wrap_texel(int i, int n, engine::TextureWrap mode) {
  switch (mode) {
    case engine::TextureWrap::ClampToEdge:
      return std::clamp(i, 0, n - 1);
    case engine::TextureWrap::MirroredRepeat: {
      const int period = 2 * n;
      int m = i % period;
      if (m < 0) m += period;
      return m < n ? m : period - 1 - m;
    }
    case engine::TextureWrap::Repeat:
    default: {
      int m = i % n;
      return m < 0 ? m + n : m;
    }
  }
}

float srgb_to_linear(std::uint8_t v) { return srgb_table()[v]; }

TextureMips build_texture_mips(const BakeImage& image, bool srgb) {
  GI_EXPECTS(
      image.width >= 1 && image.height >= 1 &&
          image.rgba8.size() == static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 4u,
      "a valid RGBA8 image (validate_bake_input checks it)");
  TextureMips mips;
  TextureMips::Level base;
  base.width = image.width;
  base.height = image.height;
  base.texels.resize(static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height));
  const auto& table = srgb_table();
  for (std::size_t i = 0; i < base.texels.size(); ++i) {
    const std::uint8_t* p = &image.rgba8[4 * i];
    const auto lin = [&](std::uint8_t c) { return srgb ? table[c] : static_cast<float>(c) / 255.0f; };
    base.texels[i] = glm::vec4(lin(p[0]), lin(p[1]), lin(p[2]), static_cast<float>(p[3]) / 255.0f);
  }
  mips.levels.push_back(std::move(base));
  while (mips.levels.back().width > 1 || mips.levels.back().height > 1) mips.levels.push_back(half(mips.levels.back()));
  return mips;
}

float mip_level(const TextureMips& mips, float uv_footprint) {
  if (mips.levels.empty()) return 0.0f;
  const TextureMips::Level& l0 = mips.levels.front();
  const float texels = uv_footprint * static_cast<float>(std::max(l0.width, l0.height));
  if (!(texels > 1.0f)) return 0.0f;
  return std::min(std::log2(texels), static_cast<float>(mips.levels.size() - 1));
}

glm::vec4 sample_texture(const TextureMips& mips, const engine::TextureSampler& sampler, glm::vec2 uv, float level) {
  GI_EXPECTS(!mips.levels.empty(), "a built mip chain");
  if (!sampler.mipmaps || !(level > 0.0f)) return bilinear(mips.levels[0], sampler, uv);
  const float top = static_cast<float>(mips.levels.size() - 1);
  level = std::min(level, top);
  const auto lo = static_cast<std::size_t>(std::floor(level));
  const float f = level - static_cast<float>(lo);
  const glm::vec4 a = bilinear(mips.levels[lo], sampler, uv);
  if (f <= 0.0f || lo + 1 >= mips.levels.size()) return a;
  return (1.0f - f) * a + f * bilinear(mips.levels[lo + 1], sampler, uv);
}

glm::vec4 sample_material_texture(const std::vector<TextureMips>& textures, const MaterialTexture& t, glm::vec2 uv,
                                  float uv_footprint) {
  const TextureMips& mips = textures[static_cast<std::size_t>(t.mips)];
  const float scale = std::max(std::fabs(t.transform.scale.x), std::fabs(t.transform.scale.y));
  const glm::vec2 st = engine::transformed_uv(t.transform, uv);
  return sample_texture(mips, t.sampler, st, mip_level(mips, uv_footprint * scale));
}

}  // namespace gi
