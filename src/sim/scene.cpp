#include "taiga/sim/scene.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "geometry_buffers.hpp"

namespace taiga::sim {
namespace {

constexpr unsigned kTriangleGeometry = 0;
constexpr unsigned kCurveGeometry = 1;

void checkDevice(RTCDevice device, const char* what) {
  const RTCError error = rtcGetDeviceError(device);
  if (error != RTC_ERROR_NONE) {
    throw std::runtime_error(std::string("Embree error ") +
                             std::to_string(static_cast<int>(error)) + " in " + what);
  }
}

/// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
Eigen::Vector3d closestOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                  const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

/// Distance from p to the surface of a cone segment from (a, ra) to (b, rb), the shape of
/// Embree's cone linear curves: beside the segment, the distance to the axis minus the radius
/// interpolated at p's axial position (exact for cylinders, a close approximation for the gentle
/// tapers of stems and branches). A free end (cap_a, cap_b) is closed by a flat disc; at a joint
/// the next segment of the chain carries on, so beyond it only the rim counts.
double distanceToCone(const Eigen::Vector3d& p, const Eigen::Vector3d& a, double ra,
                      const Eigen::Vector3d& b, double rb, bool cap_a, bool cap_b) {
  const Eigen::Vector3d ab = b - a;
  const double len2 = ab.squaredNorm();
  if (len2 <= 0) return std::max(0.0, (p - a).norm() - std::max(ra, rb));
  const double len = std::sqrt(len2);
  const double s = (p - a).dot(ab) / len2;  // unclamped axial position
  const double radial = (p - (a + s * ab)).norm();
  if (s < 0.0 || s > 1.0) {
    const double axial = (s < 0.0 ? -s : s - 1.0) * len;
    const double r_end = s < 0.0 ? ra : rb;
    const bool capped = s < 0.0 ? cap_a : cap_b;
    return capped && radial <= r_end ? axial : std::hypot(radial - r_end, axial);
  }
  const double r = ra + s * (rb - ra);
  if (radial >= r) return radial - r;
  double d = r - radial;
  if (cap_a) d = std::min(d, s * len);
  if (cap_b) d = std::min(d, (1.0 - s) * len);
  return d;
}

void segmentBounds(const RTCBoundsFunctionArguments* args) {
  const auto* g = static_cast<const detail::GeometryBuffers*>(args->geometryUserPtr);
  const float* a = &g->curve_vertices[4 * std::size_t{g->curve_indices[args->primID]}];
  const float* b = a + 4;
  const float r = std::max(a[3], b[3]);
  args->bounds_o->lower_x = std::min(a[0], b[0]) - r;
  args->bounds_o->lower_y = std::min(a[1], b[1]) - r;
  args->bounds_o->lower_z = std::min(a[2], b[2]) - r;
  args->bounds_o->upper_x = std::max(a[0], b[0]) + r;
  args->bounds_o->upper_y = std::max(a[1], b[1]) + r;
  args->bounds_o->upper_z = std::max(a[2], b[2]) + r;
}

}  // namespace

double reflectivity(Material material) {
  switch (material) {
    case Material::kGround:
      return 0.25;
    case Material::kBark:
      return 0.35;
    case Material::kBranch:
      return 0.3;
    case Material::kFoliage:
      return 0.45;
    case Material::kRock:
      return 0.3;
    case Material::kDeadWood:
      return 0.4;
    case Material::kMachine:
      return 0.5;  // yellow or green paint, some dirt
  }
  return 0.3;
}

Eigen::Vector3d Tree::axisAt(double s_m) const {
  const double pi = 3.14159265358979323846;
  const Eigen::Vector3d lean_dir(std::cos(lean_azimuth_rad), std::sin(lean_azimuth_rad), 0.0);
  const Eigen::Vector3d bend_dir(std::cos(bend_azimuth_rad), std::sin(bend_azimuth_rad), 0.0);
  return base_world + Eigen::Vector3d(0, 0, s_m) + s_m * std::tan(lean_rad) * lean_dir +
         bend_m * std::sin(pi * std::clamp(s_m / height_m, 0.0, 1.0)) * bend_dir;
}

double Tree::radiusAt(double s_m) const {
  const double r_bh = 0.5 * dbh_m;
  if (s_m < 1.3) {
    const double f = (1.3 - std::max(s_m, 0.0)) / 1.3;
    return r_bh * (1.0 + 0.3 * f * f);
  }
  return std::max(0.004, r_bh * std::pow(std::max(0.0, (height_m - s_m) / (height_m - 1.3)), 0.8));
}

struct Scene::Impl {
  ForestParams params;
  SceneLayout layout;
  Terrain terrain;
  Wind wind;
  detail::ForestContents contents;
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  /// For distance queries: the same triangles, and the curve segments as user primitives with
  /// bounds only (Embree's point queries do not visit its built-in curves).
  RTCScene query_scene = nullptr;

  Impl(const ForestParams& p, std::uint64_t seed, SceneLayout l)
      : params(p), layout(std::move(l)), terrain(p, seed), wind(p, seed) {
    contents = detail::buildForest(params, seed, layout, terrain);
    device = rtcNewDevice(nullptr);
    if (!device) throw std::runtime_error("Embree: rtcNewDevice failed");
    scene = rtcNewScene(device);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_MEDIUM);
    const detail::GeometryBuffers& g = contents.geometry;

    RTCGeometry tris = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(tris, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                               g.tri_vertices.data(), 0, 3 * sizeof(float),
                               g.tri_vertices.size() / 3);
    rtcSetSharedGeometryBuffer(tris, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                               g.tri_indices.data(), 0, 3 * sizeof(std::uint32_t),
                               g.tri_indices.size() / 3);
    rtcCommitGeometry(tris);
    rtcAttachGeometryByID(scene, tris, kTriangleGeometry);
    rtcReleaseGeometry(tris);

    if (!g.curve_indices.empty()) {
      // Cones without the spheres of round curves at the joints: what distanceToSurface measures
      // against, and about 11 % faster to cast into (sim_bench). The only difference is at the
      // joints of bent chains (a wedge of r tan(bend / 2), about 2 mm for a 2 cm branch bent by
      // 10 deg) and at free ends (flat instead of a half sphere).
      RTCGeometry curves = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_CONE_LINEAR_CURVE);
      rtcSetSharedGeometryBuffer(curves, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                 g.curve_vertices.data(), 0, 4 * sizeof(float),
                                 g.curve_vertices.size() / 4);
      rtcSetSharedGeometryBuffer(curves, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT,
                                 g.curve_indices.data(), 0, sizeof(std::uint32_t),
                                 g.curve_indices.size());
      rtcCommitGeometry(curves);
      rtcAttachGeometryByID(scene, curves, kCurveGeometry);
      rtcReleaseGeometry(curves);
    }
    rtcCommitScene(scene);
    checkDevice(device, "building the scene");

    query_scene = rtcNewScene(device);
    RTCGeometry query_tris = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(query_tris, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                               g.tri_vertices.data(), 0, 3 * sizeof(float),
                               g.tri_vertices.size() / 3);
    rtcSetSharedGeometryBuffer(query_tris, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                               g.tri_indices.data(), 0, 3 * sizeof(std::uint32_t),
                               g.tri_indices.size() / 3);
    rtcCommitGeometry(query_tris);
    rtcAttachGeometryByID(query_scene, query_tris, kTriangleGeometry);
    rtcReleaseGeometry(query_tris);
    if (!g.curve_indices.empty()) {
      RTCGeometry segments = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_USER);
      rtcSetGeometryUserPrimitiveCount(segments, static_cast<unsigned>(g.curve_indices.size()));
      rtcSetGeometryUserData(segments, const_cast<detail::GeometryBuffers*>(&g));
      rtcSetGeometryBoundsFunction(segments, &segmentBounds, nullptr);
      rtcCommitGeometry(segments);
      rtcAttachGeometryByID(query_scene, segments, kCurveGeometry);
      rtcReleaseGeometry(segments);
    }
    rtcCommitScene(query_scene);
    checkDevice(device, "building the distance-query scene");
  }
  ~Impl() {
    if (query_scene) rtcReleaseScene(query_scene);
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
};

namespace {
Eigen::Vector3d triVertex(const detail::GeometryBuffers& g, std::uint32_t index) {
  const float* v = &g.tri_vertices[3 * std::size_t{index}];
  return {v[0], v[1], v[2]};
}
Eigen::Vector4d curveVertex(const detail::GeometryBuffers& g, std::uint32_t index) {
  const float* v = &g.curve_vertices[4 * std::size_t{index}];
  return {v[0], v[1], v[2], v[3]};
}

double primitiveDistance(const detail::GeometryBuffers& g, unsigned geom, unsigned prim,
                         const Eigen::Vector3d& p) {
  if (geom == kTriangleGeometry) {
    const std::uint32_t* t = &g.tri_indices[3 * std::size_t{prim}];
    return (p - closestOnTriangle(p, triVertex(g, t[0]), triVertex(g, t[1]), triVertex(g, t[2])))
        .norm();
  }
  const std::uint32_t first = g.curve_indices[prim];
  const Eigen::Vector4d a = curveVertex(g, first), b = curveVertex(g, first + 1);
  const bool joined_before = prim > 0 && g.curve_indices[prim - 1] + 1 == first;
  const bool joined_after = prim + 1 < g.curve_indices.size() && g.curve_indices[prim + 1] == first + 1;
  return distanceToCone(p, a.head<3>(), a[3], b.head<3>(), b[3], !joined_before, !joined_after);
}

struct PointQueryState {
  const detail::GeometryBuffers* geometry;
  Eigen::Vector3d p;
  double best;
};

bool pointQueryCallback(RTCPointQueryFunctionArguments* args) {
  auto* state = static_cast<PointQueryState*>(args->userPtr);
  const double d = primitiveDistance(*state->geometry, args->geomID, args->primID, state->p);
  if (d < state->best) {
    state->best = d;
    args->query->radius = static_cast<float>(d);
    return true;
  }
  return false;
}
}  // namespace

Scene::Scene(const ForestParams& params, std::uint64_t seed, SceneLayout layout)
    : impl_(std::make_unique<Impl>(params, seed, std::move(layout))) {}
Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

std::optional<RayHit> Scene::castRay(const Eigen::Vector3d& origin_world,
                                     const Eigen::Vector3d& direction_world, double t_min_m,
                                     double t_max_m) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh{};
  rh.ray.org_x = static_cast<float>(origin_world.x());
  rh.ray.org_y = static_cast<float>(origin_world.y());
  rh.ray.org_z = static_cast<float>(origin_world.z());
  rh.ray.dir_x = static_cast<float>(direction_world.x());
  rh.ray.dir_y = static_cast<float>(direction_world.y());
  rh.ray.dir_z = static_cast<float>(direction_world.z());
  rh.ray.tnear = static_cast<float>(t_min_m);
  rh.ray.tfar = static_cast<float>(t_max_m);
  rh.ray.mask = std::numeric_limits<unsigned>::max();
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
  RayHit hit;
  hit.range_m = rh.ray.tfar;
  Eigen::Vector3d n(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
  if (n.squaredNorm() > 0) n.normalize();
  if (n.dot(direction_world) > 0) n = -n;
  hit.normal_world = n;
  const detail::GeometryBuffers& g = impl_->contents.geometry;
  hit.material = rh.hit.geomID == kTriangleGeometry ? g.tri_materials[rh.hit.primID]
                                                    : g.curve_materials[rh.hit.primID];
  if (rh.hit.geomID == kCurveGeometry) hit.curve_segment = static_cast<std::int32_t>(rh.hit.primID);
  return hit;
}

void Scene::castRays(const Eigen::Vector3d& origin_world,
                     const std::vector<Eigen::Vector3d>& directions_world, double t_max_m,
                     std::vector<std::optional<RayHit>>& hits,
                     const std::vector<double>* t_min_m) const {
  const std::size_t n = directions_world.size();
  hits.assign(n, std::nullopt);
  const detail::GeometryBuffers& g = impl_->contents.geometry;
  for (std::size_t first = 0; first < n; first += 16) {
    const std::size_t count = std::min<std::size_t>(16, n - first);
    alignas(64) int valid[16];
    alignas(64) RTCRayHit16 rh;
    for (std::size_t i = 0; i < 16; ++i) {
      const bool active = i < count;
      valid[i] = active ? -1 : 0;
      const Eigen::Vector3d& d = directions_world[first + (active ? i : 0)];
      rh.ray.org_x[i] = static_cast<float>(origin_world.x());
      rh.ray.org_y[i] = static_cast<float>(origin_world.y());
      rh.ray.org_z[i] = static_cast<float>(origin_world.z());
      rh.ray.dir_x[i] = static_cast<float>(d.x());
      rh.ray.dir_y[i] = static_cast<float>(d.y());
      rh.ray.dir_z[i] = static_cast<float>(d.z());
      rh.ray.tnear[i] = t_min_m && active ? static_cast<float>((*t_min_m)[first + i]) : 0.0f;
      rh.ray.tfar[i] = static_cast<float>(t_max_m);
      rh.ray.time[i] = 0.0f;
      rh.ray.mask[i] = std::numeric_limits<unsigned>::max();
      rh.ray.id[i] = 0;
      rh.ray.flags[i] = 0;
      rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    // The 16 beams of a packet fan out over about 11 deg of elevation: incoherent rays, for which
    // Embree's hybrid traversal is about 5 % faster than with the coherent hint (sim_bench).
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    rtcIntersect16(valid, impl_->scene, &context, &rh);
    for (std::size_t i = 0; i < count; ++i) {
      if (rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) continue;
      RayHit hit;
      hit.range_m = rh.ray.tfar[i];
      Eigen::Vector3d normal(rh.hit.Ng_x[i], rh.hit.Ng_y[i], rh.hit.Ng_z[i]);
      if (normal.squaredNorm() > 0) normal.normalize();
      if (normal.dot(directions_world[first + i]) > 0) normal = -normal;
      hit.normal_world = normal;
      hit.material = rh.hit.geomID[i] == kTriangleGeometry ? g.tri_materials[rh.hit.primID[i]]
                                                           : g.curve_materials[rh.hit.primID[i]];
      if (rh.hit.geomID[i] == kCurveGeometry)
        hit.curve_segment = static_cast<std::int32_t>(rh.hit.primID[i]);
      hits[first + i] = hit;
    }
  }
}

double Scene::distanceToSurface(const Eigen::Vector3d& p_world, double max_distance_m) const {
  RTCPointQuery query{};
  query.x = static_cast<float>(p_world.x());
  query.y = static_cast<float>(p_world.y());
  query.z = static_cast<float>(p_world.z());
  query.radius = static_cast<float>(max_distance_m);
  query.time = 0.0f;
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  PointQueryState state{&impl_->contents.geometry, p_world, max_distance_m};
  rtcPointQuery(impl_->query_scene, &query, &context, pointQueryCallback, &state);
  return state.best;
}

CurveSegment Scene::curveSegment(std::int32_t index) const {
  const detail::GeometryBuffers& g = impl_->contents.geometry;
  const auto prim = static_cast<std::size_t>(index);
  const std::uint32_t first = g.curve_indices[prim];
  const Eigen::Vector4d a = curveVertex(g, first), b = curveVertex(g, first + 1);
  CurveSegment segment;
  segment.a_world = a.head<3>();
  segment.b_world = b.head<3>();
  segment.radius_a_m = a[3];
  segment.radius_b_m = b[3];
  // Segments of one chain share their joint vertex: index i + 1 starts where i ends.
  segment.continues_before = prim > 0 && g.curve_indices[prim - 1] + 1 == first;
  segment.continues_after = prim + 1 < g.curve_indices.size() && g.curve_indices[prim + 1] == first + 1;
  return segment;
}

const Terrain& Scene::terrain() const { return impl_->terrain; }
const Wind& Scene::wind() const { return impl_->wind; }
const SceneLayout& Scene::layout() const { return impl_->layout; }
const std::vector<Tree>& Scene::trees() const { return impl_->contents.trees; }
const std::vector<Boulder>& Scene::boulders() const { return impl_->contents.boulders; }
const std::vector<FallenLog>& Scene::logs() const { return impl_->contents.logs; }
SceneStats Scene::stats() const {
  const double side = 2.0 * impl_->layout.half_size_m;
  return {impl_->contents.geometry.triangleCount(), impl_->contents.geometry.curveSegmentCount(),
          side * side / 1e4};
}

}  // namespace taiga::sim
