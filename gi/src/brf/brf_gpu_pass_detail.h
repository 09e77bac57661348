#pragma once
// Internals of BrfGpuPass shared by its two sources: brf_gpu_pass.cpp (create(), the model
// tables and uploads, static receivers, outputs) and brf_gpu_frame.cpp (run(): the frame's
// CPU side, the Phi slot table, the Phi / fit / gather dispatches). Not a public header.

#include <GL/glcorearb.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <engine/gpu/shader_program.h>
#include <engine/result.h>

#include "brf/radiance_field.h"
#include "gpu/gi_shaders.h"

namespace gi {

namespace brf_gpu_detail {

constexpr const char* kWhere = "BRF GPU pass";
constexpr std::size_t kSsboLimitBytes = std::size_t{128} << 20;  // DESIGN.md §4 (llvmpipe)
constexpr std::uint32_t kGroupSize = 64;                         // local_size_x of every brf_*.comp.glsl
constexpr std::uint32_t kMaxGroupsPerDimension = 65535;
// Texture units of brf_phi.comp.glsl's buffer textures (u_field, u_models, u_model_vertices,
// u_jobs, u_occluders, u_lod, u_lod_rows).
constexpr GLuint kFieldTextureUnit = 0, kModelTextureUnit = 1, kVertexTextureUnit = 2, kJobTextureUnit = 3,
                 kOccluderTextureUnit = 4, kLodTextureUnit = 5, kLodRowsTextureUnit = 6;
constexpr int kMaxBasis = 64;  // kMaxChannels = 64 x 16 in brf_fit.comp.glsl
// sh_data_ layout (ShData in brf_phi.comp.glsl): 26 directions as vec4s, then the pinv of
// bands 1..3, then the glossy models' lobe SH and vertex frames.
constexpr std::size_t kShDirections = 26;
constexpr std::size_t kShTableFloats = 4 * kShDirections + (3 + 5 + 7) * kShDirections;

/// BrfModel in brf_common.glsl (std430).
struct GpuModel {
  glm::vec4 centre_inner{0.0f};
  float outer_radius = 0.0f;
  std::uint32_t spheres = 0, face_resolution = 0, sh_bands = 0;
  std::uint32_t basis_count = 0, vertex_offset = 0, vertex_count = 0, psi_offset = 0;
  std::uint32_t ainv_offset = 0, field_offset = 0, field_buffer = 0, terms = 1;
  glm::vec4 box_lo{0.0f}, box_hi{0.0f};
};
static_assert(sizeof(GpuModel) == 96, "must match BrfModel in brf_common.glsl (std430)");

/// BrfInstance in brf_common.glsl (std430).
struct GpuInstance {
  glm::vec4 albedo{0.0f};
  glm::vec3 specular{0.0f};
  std::uint32_t gather_first = 0;  ///< brf_gather.comp.glsl: the instance's first invocation (kGatherVertices each).
  std::uint32_t model = 0, vertex_offset = 0, vertex_count = 0, weight_offset = 0;
  std::uint32_t live_first = 0, live_count = 0, value_offset = 0, terms = 1;
};
static_assert(sizeof(GpuInstance) == 64, "must match BrfInstance in brf_common.glsl (std430)");

static_assert(sizeof(glm::uvec2) == 8 && sizeof(glm::uvec4) == 16 && sizeof(glm::vec4) == 16,
              "uvec2 / uvec4 / vec4 arrays are uploaded as std430 arrays");

inline engine::Error error(std::string message) { return engine::Error{"", kWhere, std::move(message)}; }

inline std::size_t gl_limit(GLenum name) {
  GLint64 value = 0;
  glGetInteger64v(name, &value);
  return value > 0 ? static_cast<std::size_t>(value) : 0;
}

inline bool same_pose(const glm::mat4& a, const glm::mat4& b, float tolerance) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (std::fabs(a[c][r] - b[c][r]) > tolerance * (1.0f + std::fabs(a[c][r]))) return false;
  return true;
}

/// 2-D grid of `groups` work groups (x wraps at 65535).
inline void dispatch_groups(std::uint32_t groups) {
  if (groups == 0) return;
  const std::uint32_t gx = std::min(groups, kMaxGroupsPerDimension);
  glDispatchCompute(gx, (groups + gx - 1) / gx, 1);
}

/// Vertices per brf_gather.comp.glsl invocation (its kGatherVertices): the weights fetched once serve them all.
constexpr std::uint32_t kGatherVertices = 4;

inline std::uint32_t u32(std::size_t v) { return static_cast<std::uint32_t>(v); }

/// Basis functions padded to a multiple of 4 (brf_padded in brf_common.glsl): Phi rows and
/// weight runs are read as vec4s.
// The xyz of the first `count` vec4s of a GL buffer.
inline std::vector<glm::vec3> read_back_vec4s(std::uint32_t buffer, std::size_t count) {
  std::vector<glm::vec4> v(count);
  if (count > 0) glGetNamedBufferSubData(buffer, 0, static_cast<GLsizeiptr>(count * sizeof(glm::vec4)), v.data());
  std::vector<glm::vec3> out(count);
  for (std::size_t j = 0; j < count; ++j) out[j] = glm::vec3(v[j]);
  return out;
}

inline std::uint32_t padded(std::uint32_t basis_count) { return (basis_count + 3u) & ~3u; }

/// The field as the GPU holds it: each channel's coefficients padded to a multiple of 4
/// floats (9 -> 12 for 3 bands), so brf_phi.comp.glsl reads them as vec4s. llvmpipe (Mesa 22)
/// runs every SSBO load as a loop over the SIMD lanes, so a vec4 costs about what one float
/// does: 3 loads per (sample, channel) instead of 9, 1 for the unclamped cosine's band 1.
inline std::size_t gpu_field_floats(const BasisRadianceField& f) {
  const std::size_t cc = static_cast<std::size_t>(f.coefficient_count());
  return f.coefficients.size() / cc * padded(static_cast<std::uint32_t>(cc));
}
inline std::size_t gpu_field_bytes(const BasisRadianceField& f) { return gpu_field_floats(f) * sizeof(float); }
inline std::vector<float> gpu_field(const BasisRadianceField& f) {
  const std::size_t cc = static_cast<std::size_t>(f.coefficient_count()), cc4 = padded(static_cast<std::uint32_t>(cc));
  std::vector<float> out(gpu_field_floats(f), 0.0f);
  for (std::size_t c = 0; c < f.coefficients.size() / cc; ++c)
    std::copy_n(f.coefficients.begin() + static_cast<std::ptrdiff_t>(c * cc), cc,
                out.begin() + static_cast<std::ptrdiff_t>(c * cc4));
  return out;
}

inline engine::Result<engine::ShaderProgram> build(const char* file) {
  return engine::ShaderProgramBuilder(gi_shader_files()).stage(engine::ShaderStage::Compute, file).build();
}

inline void bind(GLuint binding, GLuint buffer) { glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, buffer); }

}  // namespace brf_gpu_detail

/// PhiJob in brf_phi.comp.glsl (std430).
struct BrfPhiJob {
  glm::mat4 to_source{1.0f};
  glm::mat4 normal_to_source{1.0f};
  std::uint32_t source_model = 0, point_offset = 0, point_count = 0, phi_offset = 0;
  glm::mat4 frame_to_source{1.0f};  // glossy receiver: its object space's rotation into the source's
  std::uint32_t rows = 1, frame_offset = 0, lobe_offset = 0;
  // Level of detail (brf_lod.h): 0, or 1 + the receiver's first representative point (kind 0)
  // / first vertex entry (kind 2) in the lod table
  std::uint32_t lod_points = 0;
  std::uint32_t occluder_offset = 0, occluder_count = 0;  // into the occluder records
  std::uint32_t lod_rows = 0;    // kind 2: first vec4 of the representative points' rows in phi_
  std::uint32_t lod_shared = 0;  // BrfUpdateSettings::lod_shared_visibility (0 / 1)
};
static_assert(sizeof(BrfPhiJob) == 240, "must match PhiJob in brf_phi.comp.glsl (std430)");

/// BrfOccluderRecord in brf_phi.comp.glsl (std430): a box in the way of a pair, with the map
/// from the source's object space into the box's.
struct GpuOccluder {
  glm::mat4 to_occluder{1.0f};
  glm::vec4 lo{0.0f}, hi{0.0f};
};
static_assert(sizeof(GpuOccluder) == 96, "must match BrfOccluderRecord in brf_phi.comp.glsl (std430)");

}  // namespace gi
