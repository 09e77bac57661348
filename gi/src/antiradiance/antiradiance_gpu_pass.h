#pragma once
// The antiradiance iteration on the GPU (Dachsbacher et al. 2007, §4): the global, push,
// local and pull passes as OpenGL 4.5 compute shaders over SSBO tables
// (gi/shaders/antiradiance_*.comp.glsl), the twin of CpuAntiradiancePasses: same tables,
// same summation order, float arithmetic, so the tests compare them entry by entry.
// run_antiradiance() drives it like the CPU twin; the residual of each local pass is read
// back (8 bytes per leaf) so the divergence check and the fallback are the same.
//   auto gpu = gi::AntiradianceGpuPass::create(h, bins, links).value();  // a GL context is current
//   gi::run_antiradiance(gpu, direct, settings);  auto e = gpu.irradiance();
//
// GL state: every call needs the creating context current and changes the bound program and
// shader-storage bindings 0-8.

#include <cstddef>
#include <cstdint>
#include <vector>

#include <engine/gpu/gl_objects.h>
#include <engine/gpu/shader_program.h>
#include <engine/result.h>

#include "antiradiance/antiradiance_passes.h"

namespace gi {

class AntiradianceGpuPass final : public AntiradiancePasses {
 public:
  /// Compiles the four shaders, uploads the hierarchy's structure, the bins and the links,
  /// allocates the tables. Keeps a reference to `h` (its node and leaf counts must not
  /// change; geometry may: reset() uploads the leaves' normals and areas). Errors: a table
  /// above the SSBO limit, shader build failure.
  static engine::Result<AntiradianceGpuPass> create(const ElementHierarchy& h, const DirectionalBins& bins,
                                                    const LinkMesh& links);

  AntiradianceGpuPass(AntiradianceGpuPass&&) noexcept = default;
  AntiradianceGpuPass& operator=(AntiradianceGpuPass&&) noexcept = delete;
  AntiradianceGpuPass(const AntiradianceGpuPass&) = delete;
  AntiradianceGpuPass& operator=(const AntiradianceGpuPass&) = delete;
  ~AntiradianceGpuPass() override = default;

  /// Uploads new links (after a relink). Error: above the SSBO limit.
  engine::Status set_links(const LinkMesh& links);

  void reset(std::span<const glm::vec3> direct) override;
  void warm_start(std::span<const glm::vec3> direct) override;
  void global() override;
  void push() override;
  LocalPassSums local(bool radiance, bool antiradiance) override;
  void pull() override;
  std::vector<glm::vec3> irradiance() const override;

  /// The exitant table read back (nodes x bins RGB), for tests.
  std::vector<glm::vec3> exitant() const;
  /// GPU memory held (bytes).
  std::size_t gpu_bytes() const;

 private:
  explicit AntiradianceGpuPass(const ElementHierarchy& h) : h_(&h) {}
  void dispatch(const engine::ShaderProgram& program, std::uint32_t items);
  void set_first(const engine::ShaderProgram& program, std::uint32_t first);
  /// Uploads the leaves' normals, areas, albedos and `direct`.
  void upload_leaves(std::span<const glm::vec3> direct);

  const ElementHierarchy* h_;
  std::uint32_t m_ = 0;
  std::uint32_t nodes_ = 0;
  std::uint32_t leaves_ = 0;
  engine::ShaderProgram global_, push_, local_, pull_;
  std::uint32_t runs_count_ = 0;
  engine::GlBuffer runs_, links_, parents_, leaf_nodes_, child_range_, children_, by_level_, bins_, leaf_data_;
  engine::GlBuffer i_ex_, l_in_, i_l_, i_a_, irradiance_, residual_;
  std::vector<std::uint32_t> level_offsets_;
  std::size_t bytes_ = 0;
  std::size_t link_bytes_ = 0;
};

}  // namespace gi
