#include "lumar/lighting/ray_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <mutex>
#include <vector>

#include "embree_device.h"
#include "lumar/base/error.h"

namespace lumar {

namespace {

RTCGeometry make_triangles(RTCDevice device, const Mesh& mesh) {
  RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                        3 * sizeof(float), mesh.positions.size()));
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    v[3 * i + 0] = mesh.positions[i].x;
    v[3 * i + 1] = mesh.positions[i].y;
    v[3 * i + 2] = mesh.positions[i].z;
  }
  auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                             3 * sizeof(unsigned), mesh.triangle_count()));
  std::copy(mesh.indices.begin(), mesh.indices.end(), idx);
  rtcCommitGeometry(geom);
  return geom;
}

void set_transform(RTCGeometry instance, const glm::dmat4& m) {
  float xfm[12];  // 3x4 column-major: the upper three rows of each column
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 3; ++r) xfm[c * 3 + r] = float(m[c][r]);
  rtcSetGeometryTransform(instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
  rtcCommitGeometry(instance);
}

RTCRay to_rtc(const Ray& ray) {
  RTCRay r{};
  r.org_x = ray.origin.x, r.org_y = ray.origin.y, r.org_z = ray.origin.z;
  r.dir_x = ray.direction.x, r.dir_y = ray.direction.y, r.dir_z = ray.direction.z;
  r.tnear = ray.t_near;
  r.tfar = ray.t_far;
  r.mask = 0xFFFFFFFFu;
  r.flags = 0;
  return r;
}

}  // namespace

struct RayScene::Impl {
  RTCDevice device = embree_device();
  RTCScene top = rtcNewScene(device);
  std::vector<RTCScene> instanced;     // one scene per instance's mesh
  std::vector<RTCGeometry> instances;  // instance geometries, by instance id
  std::vector<glm::dmat4> instance_to_world;
  std::vector<unsigned> static_geom_ids;
  bool any_geometry = false;

  // Instance ids are attach order among instances; find ours by its geometry id.
  int instance_index(unsigned geom_id) const {
    RTCGeometry g = rtcGetGeometry(top, geom_id);
    return int(std::find(instances.begin(), instances.end(), g) - instances.begin());
  }
  // A hit's geometric normal in world space (Embree's Ng is in the instance's own space).
  glm::dvec3 world_normal(unsigned instance_geom_id, const glm::dvec3& ng) const {
    if (instance_geom_id == RTC_INVALID_GEOMETRY_ID) return ng;
    const glm::dmat4& m = instance_to_world[std::size_t(instance_index(instance_geom_id))];
    return glm::transpose(glm::inverse(glm::dmat3(m))) * ng;
  }

  // The second look at a front-face hit's distance (see intersect): the context carries
  // the scene and the ray's world direction, and only back faces pass.
  struct BackFaceContext {
    RTCIntersectContext context;
    const Impl* impl;
    glm::dvec3 world_direction;
  };
  static void keep_back_faces(const RTCFilterFunctionNArguments* args) {
    const auto* c = reinterpret_cast<const BackFaceContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
      if (args->valid[i] == 0) continue;
      const glm::dvec3 ng(RTCHitN_Ng_x(args->hit, args->N, i), RTCHitN_Ng_y(args->hit, args->N, i),
                          RTCHitN_Ng_z(args->hit, args->N, i));
      const glm::dvec3 n = c->impl->world_normal(RTCHitN_instID(args->hit, args->N, i, 0), ng);
      if (!(glm::dot(n, c->world_direction) > 0.0)) args->valid[i] = 0;
    }
  }

  ~Impl() {
    for (RTCGeometry g : instances) rtcReleaseGeometry(g);
    for (RTCScene s : instanced) rtcReleaseScene(s);
    rtcReleaseScene(top);
  }
};

RayScene::RayScene() : impl_(std::make_unique<Impl>()) {
  rtcSetSceneBuildQuality(impl_->top, RTC_BUILD_QUALITY_LOW);            // the top level changes every frame
  rtcSetSceneFlags(impl_->top, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);  // keep_back_faces
}
RayScene::~RayScene() = default;

std::uint32_t RayScene::add_static(const Mesh& world_mesh) {
  const auto index = std::uint32_t(impl_->static_geom_ids.size());
  if (world_mesh.triangle_count() == 0) {
    impl_->static_geom_ids.push_back(RTC_INVALID_GEOMETRY_ID);
    return index;
  }
  RTCGeometry geom = make_triangles(impl_->device, world_mesh);
  impl_->static_geom_ids.push_back(rtcAttachGeometry(impl_->top, geom));
  rtcReleaseGeometry(geom);
  impl_->any_geometry = true;
  return index;
}

int RayScene::add_instance(const Mesh& model_mesh, const glm::dmat4& T_world_model) {
  RTCScene scene = rtcNewScene(impl_->device);
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);  // built once, traced many times
  rtcSetSceneFlags(scene, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
  if (model_mesh.triangle_count() > 0) {
    RTCGeometry geom = make_triangles(impl_->device, model_mesh);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
  }
  rtcCommitScene(scene);
  RTCGeometry instance = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_INSTANCE);
  rtcSetGeometryInstancedScene(instance, scene);
  set_transform(instance, T_world_model);
  const unsigned geom_id = rtcAttachGeometry(impl_->top, instance);
  impl_->instanced.push_back(scene);
  impl_->instances.push_back(instance);
  impl_->instance_to_world.push_back(T_world_model);
  impl_->any_geometry = impl_->any_geometry || model_mesh.triangle_count() > 0;
  (void)geom_id;
  return int(impl_->instances.size()) - 1;
}

void RayScene::set_instance_transform(int id, const glm::dmat4& T_world_model) {
  if (id < 0 || id >= int(impl_->instances.size())) throw RuntimeError("RayScene: no instance " + std::to_string(id));
  impl_->instance_to_world[std::size_t(id)] = T_world_model;
  set_transform(impl_->instances[std::size_t(id)], T_world_model);
}

void RayScene::commit() { rtcCommitScene(impl_->top); }

bool RayScene::empty() const { return !impl_->any_geometry; }

std::optional<RayHit> RayScene::intersect(const Ray& ray) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh{};
  rh.ray = to_rtc(ray);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->top, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;

  const glm::dvec3 direction(ray.direction);
  glm::dvec3 n = impl_->world_normal(rh.hit.instID[0], glm::dvec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
  if (!(glm::dot(n, direction) > 0.0)) {
    // Two faces at the same distance (a box standing on the floor, a wall meeting the
    // ceiling) are a tie that Embree's kernels break differently on different CPUs. A
    // back face there means the ray starts inside geometry, so it wins: look again,
    // within a hair of the hit, for back faces only.
    const float t = rh.ray.tfar;
    const float hair = 1e-5f * t + 1e-6f / std::max(glm::length(ray.direction), 1e-12f);
    Impl::BackFaceContext back{{}, impl_.get(), direction};
    rtcInitIntersectContext(&back.context);
    back.context.filter = Impl::keep_back_faces;
    RTCRayHit again{};
    again.ray = to_rtc(ray);
    again.ray.tnear = std::max(ray.t_near, t - hair);
    again.ray.tfar = std::min(ray.t_far, t + hair);
    again.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    again.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(impl_->top, &back.context, &again);
    if (again.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
      rh = again;
      n = impl_->world_normal(rh.hit.instID[0], glm::dvec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
    }
  }

  RayHit hit;
  hit.t = rh.ray.tfar;
  hit.triangle = rh.hit.primID;
  if (rh.hit.instID[0] != RTC_INVALID_GEOMETRY_ID) {
    hit.instance = impl_->instance_index(rh.hit.instID[0]);
  } else {
    const auto it = std::find(impl_->static_geom_ids.begin(), impl_->static_geom_ids.end(), rh.hit.geomID);
    hit.mesh = std::uint32_t(it - impl_->static_geom_ids.begin());
  }
  n = glm::normalize(n);
  hit.back_face = glm::dot(n, direction) > 0.0;
  hit.normal = glm::vec3(hit.back_face ? -n : n);
  return hit;
}

bool RayScene::occluded(const Ray& ray) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay r = to_rtc(ray);
  rtcOccluded1(impl_->top, &context, &r);
  return r.tfar < 0.0f;  // Embree marks a blocked ray with tfar = -inf
}

void RayScene::occluded(std::span<const Ray> rays, std::span<std::uint8_t> blocked, bool coherent) const {
  if (blocked.size() < rays.size()) throw RuntimeError("RayScene::occluded: output shorter than the rays");
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  if (coherent) context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  constexpr std::size_t kChunk = 256;
  RTCRay chunk[kChunk];
  for (std::size_t start = 0; start < rays.size(); start += kChunk) {
    const std::size_t n = std::min(kChunk, rays.size() - start);
    for (std::size_t i = 0; i < n; ++i) chunk[i] = to_rtc(rays[start + i]);
    rtcOccluded1M(impl_->top, &context, chunk, unsigned(n), sizeof(RTCRay));
    for (std::size_t i = 0; i < n; ++i) blocked[start + i] = chunk[i].tfar < 0.0f ? 1 : 0;
  }
}

}  // namespace lumar
