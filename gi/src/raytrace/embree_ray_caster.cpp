#include "raytrace/embree_ray_caster.h"

#include <embree3/rtcore.h>
#include <engine/check.h>
#include <engine/finite.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace gi {
namespace {

// Embree's error callback: keeps the first message for the engine::Error that build()
// returns (the library never prints). `user` is the caster's message string.
void embree_error(void* user, RTCError code, const char* message) {
  auto& first = *static_cast<std::string*>(user);
  if (first.empty()) first = "error " + std::to_string(static_cast<int>(code)) + ": " + (message ? message : "");
}

// Move-only owners of Embree handles (RAII; moved-from state is empty).
struct DeviceHandle {
  RTCDevice h = nullptr;
  DeviceHandle() = default;
  explicit DeviceHandle(RTCDevice d) : h(d) {}
  DeviceHandle(DeviceHandle&& o) noexcept : h(std::exchange(o.h, nullptr)) {}
  DeviceHandle& operator=(DeviceHandle&& o) noexcept {
    if (this != &o) {
      if (h) rtcReleaseDevice(h);
      h = std::exchange(o.h, nullptr);
    }
    return *this;
  }
  ~DeviceHandle() {
    if (h) rtcReleaseDevice(h);
  }
};

struct SceneHandle {
  RTCScene h = nullptr;
  SceneHandle() = default;
  explicit SceneHandle(RTCScene s) : h(s) {}
  SceneHandle(SceneHandle&& o) noexcept : h(std::exchange(o.h, nullptr)) {}
  SceneHandle& operator=(SceneHandle&& o) noexcept {
    if (this != &o) {
      if (h) rtcReleaseScene(h);
      h = std::exchange(o.h, nullptr);
    }
    return *this;
  }
  ~SceneHandle() {
    if (h) rtcReleaseScene(h);
  }
};

// Intersection and occlusion filter of a geometry with cut-outs (alpha MASK / BLEND): a hit
// where the alpha is below the cutoff is rejected, so the ray goes on. Embree calls it for
// single rays and for every lane of a packet alike (valid[i] == 0: no hit to judge).
// `geometryUserPtr` is the RtGeometry.
void cutout_filter(const RTCFilterFunctionNArguments* args) {
  const auto* geo = static_cast<const RtGeometry*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    const std::uint32_t prim = RTCHitN_primID(args->hit, args->N, i);
    const glm::vec2 bary(RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i));
    if (geo->cutout->cut(geo->indices, prim, bary)) args->valid[i] = 0;
  }
}

// The scene's indices, positions, instance geometries and transforms checked before Embree sees them.
engine::Status check_scene_data(const RtSceneData& data) {
  for (std::size_t g = 0; g < data.geometries.size(); ++g) {
    const RtGeometry& geo = data.geometries[g];
    const std::string where = "geometry " + std::to_string(g);
    if (geo.indices.size() % 3 != 0) return engine::Error{"", where, "index count is not a multiple of 3"};
    for (std::uint32_t i : geo.indices)
      if (i >= geo.positions.size()) return engine::Error{"", where, "index " + std::to_string(i) + " out of range"};
    for (const glm::vec3& p : geo.positions)
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        return engine::Error{"", where, "non-finite vertex position"};
  }
  for (std::size_t i = 0; i < data.instances.size(); ++i) {
    if (data.instances[i].geometry >= data.geometries.size())
      return engine::Error{"", "instance " + std::to_string(i), "geometry index out of range"};
    if (!engine::all_finite(data.instances[i].object_to_world))
      return engine::Error{"", "instance " + std::to_string(i), "non-finite transform"};
  }
  return {};
}

class EmbreeRayCaster final : public RayCaster {
 public:
  engine::Status build(const RtSceneData& data) {
    data_ = data;
    static_normals_.clear();
    static_normal_of_.clear();
    if (auto ok = check_scene_data(data_); !ok) return ok;

    device_ = DeviceHandle(rtcNewDevice(nullptr));
    if (!device_.h) return engine::Error{"", "embree", "rtcNewDevice failed"};
    rtcSetDeviceErrorFunction(device_.h, embree_error, &embree_message_);
    top_ = SceneHandle(rtcNewScene(device_.h));
    rtcSetSceneBuildQuality(top_.h, RTC_BUILD_QUALITY_HIGH);

    blas_.resize(data_.geometries.size());
    for (std::size_t i = 0; i < data_.instances.size(); ++i) {
      const RtInstance& inst = data_.instances[i];
      const RtGeometry& geo = data_.geometries[inst.geometry];
      unsigned id = 0;
      if (inst.dynamic) {
        if (!blas_[inst.geometry].h) {
          blas_[inst.geometry] = SceneHandle(rtcNewScene(device_.h));
          attach_triangles(blas_[inst.geometry].h, geo, glm::mat4(1.0f));
          rtcCommitScene(blas_[inst.geometry].h);
        }
        RTCGeometry g = rtcNewGeometry(device_.h, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(g, blas_[inst.geometry].h);
        rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &inst.object_to_world[0][0]);
        rtcCommitGeometry(g);
        id = rtcAttachGeometry(top_.h, g);
        rtcReleaseGeometry(g);
      } else {
        id = attach_triangles(top_.h, geo, inst.object_to_world);
        // A static instance's world-space normals never change: computed once here (the same
        // arithmetic as for a dynamic one in to_hit), a hit then reads one value instead of
        // an instance matrix, three indices and three vertices (a third of a light-atlas
        // gather's time on the demo level went there).
        std::vector<glm::vec3>& normals = static_normals_.emplace_back();
        normals.resize(geo.indices.size() / 3);
        for (std::size_t t = 0; t < normals.size(); ++t)
          normals[t] = world_normal(inst, geo, static_cast<std::uint32_t>(t));
      }
      static_normal_of_.push_back(inst.dynamic ? kNoStaticNormals
                                               : static_cast<std::uint32_t>(static_normals_.size() - 1));
      GI_EXPECTS(id == i, "Embree geometry ids follow instance order");
    }
    rtcCommitScene(top_.h);
    if (rtcGetDeviceError(device_.h) != RTC_ERROR_NONE)
      return engine::Error{"", "embree",
                           "scene build failed" + (embree_message_.empty() ? "" : ": " + embree_message_)};
    return {};
  }

  Hit intersect(const Ray& ray) const override {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh = to_embree(ray);
    rtcIntersect1(top_.h, &ctx, &rh);
    return to_hit(rh);
  }

  Hit intersect_without_normal(const Ray& ray) const override {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh = to_embree(ray);
    rtcIntersect1(top_.h, &ctx, &rh);
    return to_hit(rh, false);
  }

  bool occluded(const Ray& ray) const override {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay r = to_embree(ray).ray;
    rtcOccluded1(top_.h, &ctx, &r);
    return r.tfar < 0.0f;
  }

  /// Lane j of a 16-ray packet (intersect_many, occluded_coherent), its id j.
  static void set_lane(RTCRay16& packet, std::size_t j, const RTCRay& r) {
    packet.org_x[j] = r.org_x;
    packet.org_y[j] = r.org_y;
    packet.org_z[j] = r.org_z;
    packet.tnear[j] = r.tnear;
    packet.dir_x[j] = r.dir_x;
    packet.dir_y[j] = r.dir_y;
    packet.dir_z[j] = r.dir_z;
    packet.time[j] = r.time;
    packet.tfar[j] = r.tfar;
    packet.mask[j] = r.mask;
    packet.id[j] = static_cast<unsigned>(j);
    packet.flags[j] = r.flags;
  }

  // Packets of 16 (Embree's widest; it splits them on narrower machines): a stream whose
  // rays share an origin or run side by side traverses the tree once per packet. The same
  // watertight triangle test as rtcIntersect1, so the hits are the same.
  void intersect_many(std::span<const Ray> rays, std::span<Hit> hits) const override {
    GI_EXPECTS(rays.size() == hits.size(), "one hit per ray");
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    constexpr std::size_t kWidth = 16;
    alignas(64) RTCRayHit16 packet;
    alignas(64) int valid[kWidth];
    for (std::size_t first = 0; first < rays.size(); first += kWidth) {
      const std::size_t n = std::min(kWidth, rays.size() - first);
      for (std::size_t j = 0; j < kWidth; ++j) {
        valid[j] = j < n ? -1 : 0;
        set_lane(packet.ray, j, to_embree(rays[first + std::min(j, n - 1)]).ray);
        packet.hit.geomID[j] = RTC_INVALID_GEOMETRY_ID;
        packet.hit.instID[0][j] = RTC_INVALID_GEOMETRY_ID;
      }
      rtcIntersect16(valid, top_.h, &ctx, &packet);
      for (std::size_t j = 0; j < n; ++j) {
        RTCRayHit rh{};
        rh.ray.tfar = packet.ray.tfar[j];
        rh.hit.geomID = packet.hit.geomID[j];
        rh.hit.instID[0] = packet.hit.instID[0][j];
        rh.hit.primID = packet.hit.primID[j];
        rh.hit.u = packet.hit.u[j];
        rh.hit.v = packet.hit.v[j];
        hits[first + j] = to_hit(rh);
      }
    }
  }

  void occluded_many(std::span<const Ray> rays, std::span<std::uint8_t> out) const override {
    GI_EXPECTS(rays.size() == out.size(), "one result per ray");
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    std::vector<RTCRay> batch(rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) batch[i] = to_embree(rays[i]).ray;
    rtcOccluded1M(top_.h, &ctx, batch.data(), static_cast<unsigned>(batch.size()), sizeof(RTCRay));
    for (std::size_t i = 0; i < rays.size(); ++i) out[i] = batch[i].tfar < 0.0f ? 1 : 0;
  }

  // Packets of 16 with the coherent flag, as intersect_many: shadow rays towards one light
  // converge, so a packet traverses the tree together. The same triangle test as
  // rtcOccluded1, so the same answers (EmbreeRayCaster.CoherentOcclusionMatchesSingleRays).
  void occluded_coherent(std::span<const Ray> rays, std::span<std::uint8_t> out) const override {
    GI_EXPECTS(rays.size() == out.size(), "one result per ray");
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    constexpr std::size_t kWidth = 16;
    alignas(64) RTCRay16 packet;
    alignas(64) int valid[kWidth];
    for (std::size_t first = 0; first < rays.size(); first += kWidth) {
      const std::size_t n = std::min(kWidth, rays.size() - first);
      for (std::size_t j = 0; j < kWidth; ++j) {
        valid[j] = j < n ? -1 : 0;
        set_lane(packet, j, to_embree(rays[first + std::min(j, n - 1)]).ray);
      }
      rtcOccluded16(valid, top_.h, &ctx, &packet);
      for (std::size_t j = 0; j < n; ++j) out[first + j] = packet.tfar[j] < 0.0f ? 1 : 0;
    }
  }

  void set_instance_transform(std::uint32_t instance, const glm::mat4& object_to_world) override {
    GI_EXPECTS(instance < data_.instances.size(), "instance index out of range");
    GI_EXPECTS(data_.instances[instance].dynamic, "only dynamic instances can move");
    GI_EXPECTS(engine::all_finite(object_to_world), "instance transforms must be finite");
    data_.instances[instance].object_to_world = object_to_world;
    RTCGeometry g = rtcGetGeometry(top_.h, instance);
    rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &object_to_world[0][0]);
    rtcCommitGeometry(g);
  }

  void commit() override { rtcCommitScene(top_.h); }

  RTCScene top() const { return top_.h; }

 private:
  unsigned attach_triangles(RTCScene scene, const RtGeometry& geo, const glm::mat4& m) {
    RTCGeometry g = rtcNewGeometry(device_.h, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), geo.positions.size()));
    for (std::size_t i = 0; i < geo.positions.size(); ++i) {
      const glm::vec3 p = glm::vec3(m * glm::vec4(geo.positions[i], 1.0f));
      v[3 * i + 0] = p.x;
      v[3 * i + 1] = p.y;
      v[3 * i + 2] = p.z;
    }
    auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                               3 * sizeof(unsigned), geo.indices.size() / 3));
    for (std::size_t i = 0; i < geo.indices.size(); ++i) idx[i] = geo.indices[i];
    if (geo.cutout) {  // `geo` lives in data_, which outlives the Embree scene
      rtcSetGeometryUserData(g, const_cast<RtGeometry*>(&geo));
      rtcSetGeometryIntersectFilterFunction(g, cutout_filter);
      rtcSetGeometryOccludedFilterFunction(g, cutout_filter);
    }
    rtcCommitGeometry(g);
    const unsigned id = rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    return id;
  }

  static RTCRayHit to_embree(const Ray& ray) {
    RTCRayHit rh{};
    rh.ray.org_x = ray.origin.x;
    rh.ray.org_y = ray.origin.y;
    rh.ray.org_z = ray.origin.z;
    rh.ray.tnear = ray.t_min;
    rh.ray.dir_x = ray.direction.x;
    rh.ray.dir_y = ray.direction.y;
    rh.ray.dir_z = ray.direction.z;
    rh.ray.time = 0.0f;
    rh.ray.tfar = ray.t_max;
    rh.ray.mask = 0xffffffffu;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    return rh;
  }

  Hit to_hit(const RTCRayHit& rh, bool normal = true) const {
    Hit h;
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return h;
    const std::uint32_t inst = rh.hit.instID[0] != RTC_INVALID_GEOMETRY_ID ? rh.hit.instID[0] : rh.hit.geomID;
    const RtInstance& instance = data_.instances[inst];
    const RtGeometry& geo = data_.geometries[instance.geometry];
    h.t = rh.ray.tfar;
    h.instance = inst;
    h.geometry = instance.geometry;
    h.primitive = rh.hit.primID;
    h.barycentric = {rh.hit.u, rh.hit.v};
    if (!normal) return h;
    // The geometric normal from the world-space triangle (independent of Embree's
    // instance-space conventions).
    const std::uint32_t s = static_normal_of_[inst];
    h.geometric_normal =
        s != kNoStaticNormals ? static_normals_[s][h.primitive] : world_normal(instance, geo, h.primitive);
    return h;
  }

  static glm::vec3 world_normal(const RtInstance& instance, const RtGeometry& geo, std::uint32_t primitive) {
    const glm::mat4& m = instance.object_to_world;
    const glm::vec3 p0 = glm::vec3(m * glm::vec4(geo.positions[geo.indices[3 * primitive + 0]], 1.0f));
    const glm::vec3 p1 = glm::vec3(m * glm::vec4(geo.positions[geo.indices[3 * primitive + 1]], 1.0f));
    const glm::vec3 p2 = glm::vec3(m * glm::vec4(geo.positions[geo.indices[3 * primitive + 2]], 1.0f));
    return glm::cross(p1 - p0, p2 - p0);
  }

  static constexpr std::uint32_t kNoStaticNormals = 0xffffffffu;
  std::vector<std::vector<glm::vec3>> static_normals_;  ///< Per static instance (in instance order).
  std::vector<std::uint32_t> static_normal_of_;  ///< Per instance: index into static_normals_, or kNoStaticNormals.

  RtSceneData data_;
  std::string embree_message_;  // declared before the device, which may call back until released
  DeviceHandle device_;
  SceneHandle top_;
  std::vector<SceneHandle> blas_;
};

}  // namespace

engine::Result<std::unique_ptr<RayCaster>> make_embree_ray_caster(const RtSceneData& data) {
  auto caster = std::make_unique<EmbreeRayCaster>();
  if (engine::Status s = caster->build(data); !s) return s.error();
  return std::unique_ptr<RayCaster>(std::move(caster));
}

void* embree_scene_handle(const RayCaster& caster) {
  const auto* e = dynamic_cast<const EmbreeRayCaster*>(&caster);
  GI_EXPECTS(e != nullptr, "not an Embree ray caster");
  return e->top();
}

}  // namespace gi
