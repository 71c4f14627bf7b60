#include "depth/depth_fusion.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

namespace sdfg {

namespace {

constexpr uint32_t kMaxNodes = 256;  // per axis

}  // namespace

std::optional<Error> DepthFusionOptions::validate() const {
  if (!(voxel > 0.0f) || !(size > voxel) || !std::isfinite(size))
    return makeError(Status::invalid_argument, "depth fusion: size and voxel must be positive");
  if (size / voxel >= float(kMaxNodes - 1))
    return makeError(Status::invalid_argument,
                     "depth fusion: more than 255 voxels per axis (size / voxel)");
  if (!(truncation >= voxel) || !std::isfinite(truncation))
    return makeError(Status::invalid_argument,
                     "depth fusion: the truncation band must be at least one voxel");
  if (!(behindThickness >= 0.0f) || !(handMargin >= 0.0f) || !std::isfinite(behindThickness) ||
      !std::isfinite(handMargin))
    return makeError(Status::invalid_argument,
                     "depth fusion: behindThickness and handMargin must be finite and >= 0");
  if (!(maxWeight >= 1.0f) || !(forgetAfter > 0.0))
    return makeError(Status::invalid_argument,
                     "depth fusion: maxWeight must be >= 1 and forgetAfter positive");
  return std::nullopt;
}

Result<DepthFusion> DepthFusion::create(const DepthFusionOptions& options) {
  if (auto e = options.validate()) return *e;
  return DepthFusion(options);
}

DepthFusion::DepthFusion(const DepthFusionOptions& options)
    : options_(options), n_(uint32_t(std::ceil(options.size / options.voxel)) + 1) {
  const size_t count = size_t(n_) * n_ * n_;
  value_.assign(count, options_.truncation);
  weight_.assign(count, 0.0f);
  seen_.assign(count, 0.0);
  volume_ = DistanceVolume(glm::vec3(corner_) * options_.voxel, options_.voxel, glm::uvec3(n_),
                           options_.truncation);
}

void DepthFusion::recentre(const glm::vec3& centre) {
  const glm::ivec3 corner =
      glm::ivec3(glm::round(centre / options_.voxel)) - glm::ivec3(int(n_ / 2));
  const glm::ivec3 shift = corner - corner_;
  if (shift == glm::ivec3(0)) return;
  std::vector<float> value(value_.size(), options_.truncation), weight(weight_.size(), 0.0f);
  std::vector<double> seen(seen_.size(), 0.0);
  const int n = int(n_);
  for (int k = 0; k < n; ++k) {
    const int ok = k + shift.z;
    if (ok < 0 || ok >= n) continue;
    for (int j = 0; j < n; ++j) {
      const int oj = j + shift.y;
      if (oj < 0 || oj >= n) continue;
      for (int i = 0; i < n; ++i) {
        const int oi = i + shift.x;
        if (oi < 0 || oi >= n) continue;
        const size_t from = index(uint32_t(oi), uint32_t(oj), uint32_t(ok));
        const size_t to = index(uint32_t(i), uint32_t(j), uint32_t(k));
        value[to] = value_[from];
        weight[to] = weight_[from];
        seen[to] = seen_[from];
      }
    }
  }
  value_ = std::move(value);
  weight_ = std::move(weight);
  seen_ = std::move(seen);
  // volume() stays what it was (true where it was) until the next finishFrame() rebuilds it here.
  corner_ = corner;
}

Status DepthFusion::integrate(const DepthView& view, std::span<const float> depth,
                              std::span<const DepthExclusion> hand, double time) {
  if (view.validate()) return Status::invalid_argument;
  if (depth.size() != size_t(view.width) * view.height) return Status::invalid_argument;
  const float tau = options_.truncation;
  const Pose viewFromWorld = view.worldFromView.inverse();
  const float tl = std::tan(view.fov.left), tr = std::tan(view.fov.right);
  const float tu = std::tan(view.fov.up), td = std::tan(view.fov.down);
  const float sx = float(view.width) / (tr - tl), sy = float(view.height) / (tu - td);

  // The cube's footprint in the image (all of it when a corner is behind the view).
  const float edge = options_.voxel * float(n_ - 1);
  const glm::vec3 origin = glm::vec3(corner_) * options_.voxel;
  int x0 = 0, y0 = 0, x1 = int(view.width), y1 = int(view.height);
  {
    glm::vec2 lo(std::numeric_limits<float>::infinity()), hi(-lo);
    bool all = true;
    for (int c = 0; c < 8 && all; ++c) {
      const glm::vec3 p = origin + edge * glm::vec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
      glm::vec2 pixel;
      float z;
      all = view.project(p, pixel, z);
      lo = glm::min(lo, pixel);
      hi = glm::max(hi, pixel);
    }
    if (all) {
      x0 = std::clamp(int(std::floor(lo.x)), 0, int(view.width));
      y0 = std::clamp(int(std::floor(lo.y)), 0, int(view.height));
      x1 = std::clamp(int(std::ceil(hi.x)) + 1, 0, int(view.width));
      y1 = std::clamp(int(std::ceil(hi.y)) + 1, 0, int(view.height));
    }
  }
  if (x0 >= x1 || y0 >= y1) return Status::ok;  // the view does not see the cube

  // The hand's own pixels in the footprint.
  handMask_.assign(depth.size(), 0);
  if (!hand.empty()) {
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; ++x) {
        const size_t px = size_t(y) * view.width + size_t(x);
        const float z = view.distance(depth[px]);
        if (!std::isfinite(z)) continue;
        const glm::vec3 p = view.worldFromView.transformPoint(
            view.ray(glm::vec2(float(x) + 0.5f, float(y) + 0.5f)) * z);
        for (const DepthExclusion& s : hand) {
          const float r = s.radius + options_.handMargin;
          const glm::vec3 d = p - s.centre;
          if (glm::dot(d, d) < r * r) {
            handMask_[px] = 1;
            break;
          }
        }
      }
    }
  }

  const float maxWeight = options_.maxWeight, behind = -options_.behindThickness;
  for (uint32_t k = 0; k < n_; ++k) {
    for (uint32_t j = 0; j < n_; ++j) {
      for (uint32_t i = 0; i < n_; ++i) {
        const glm::vec3 v = viewFromWorld.transformPoint(
            origin + options_.voxel * glm::vec3(float(i), float(j), float(k)));
        const float zx = -v.z;
        if (!(zx > 0.0f)) continue;
        const float fx = (v.x / zx - tl) * sx, fy = (tu - v.y / zx) * sy;
        if (!(fx >= float(x0) && fx < float(x1) && fy >= float(y0) && fy < float(y1))) continue;
        const size_t px = size_t(fy) * view.width + size_t(fx);
        const size_t n = index(i, j, k);
        // Behind the hand's own pixels the scene is hidden, not gone: what was fused there stays
        // as fresh as if seen (a hand resting on an object for a second would otherwise have the
        // surface under it forgotten, though nothing showed it leave).
        if (handMask_[px] != 0) {
          if (weight_[n] > 0.0f) seen_[n] = time;
          continue;
        }
        const float zs = view.distance(depth[px]);
        if (std::isnan(zs)) continue;  // a value the view cannot hold: no observation
        // Along the ray, not the axis: the voxel's distance from the surface its pixel saw.
        const float along = (zs - zx) * (glm::length(v) / zx);
        if (along < behind) continue;  // farther behind than the prior: unobserved
        const float obs = std::clamp(along, -tau, tau);
        const float w = weight_[n];
        value_[n] = (value_[n] * w + obs) / (w + 1.0f);
        weight_[n] = std::min(w + 1.0f, maxWeight);
        seen_[n] = time;
      }
    }
  }
  return Status::ok;
}

void DepthFusion::finishFrame(double time) {
  for (size_t n = 0; n < value_.size(); ++n) {
    if (weight_[n] > 0.0f && time - seen_[n] > options_.forgetAfter) {
      weight_[n] = 0.0f;
      value_[n] = options_.truncation;
    }
  }
  refreshVolume();
}

void DepthFusion::refreshVolume() {
  const float tau = options_.truncation;
  // The fused values are distances along the view rays, which overstate the distance to a
  // surface seen at a grazing angle (beside a silhouette, the ray passes the object and meets the
  // table far behind). They keep the sign; the magnitude is the Euclidean distance to the fused
  // surface (where the sign changes between neighbouring nodes, placed linearly), within the
  // band: exact within two voxels of the surface, then each node takes the nearest of its
  // neighbours' nearest surface points, in one pass forward and one back through the grid (a
  // vector distance transform: the distance to a real surface point, never a path along the grid).
  auto fused = [&](size_t v) { return weight_[v] > 0.0f ? value_[v] : tau; };
  const int n = int(n_);
  surface_.clear();
  const glm::ivec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const float a = fused(index(uint32_t(i), uint32_t(j), uint32_t(k)));
        for (const glm::ivec3& s : axes) {
          const glm::ivec3 q = glm::ivec3(i, j, k) + s;
          if (q.x >= n || q.y >= n || q.z >= n) continue;
          const float b = fused(index(uint32_t(q.x), uint32_t(q.y), uint32_t(q.z)));
          if ((a < 0.0f) == (b < 0.0f)) continue;
          surface_.push_back(glm::vec3(float(i), float(j), float(k)) +
                             (a / (a - b)) * glm::vec3(s));
        }
      }
    }
  }
  const size_t count = value_.size();
  nearest_.assign(count, -1);
  distance_.assign(count, std::numeric_limits<float>::infinity());
  for (size_t p = 0; p < surface_.size(); ++p) {
    const glm::vec3& g = surface_[p];
    const glm::ivec3 lo = glm::max(glm::ivec3(glm::floor(g)) - 1, glm::ivec3(0));
    const glm::ivec3 hi = glm::min(glm::ivec3(glm::floor(g)) + 2, glm::ivec3(n - 1));
    for (int k = lo.z; k <= hi.z; ++k)
      for (int j = lo.y; j <= hi.y; ++j)
        for (int i = lo.x; i <= hi.x; ++i) {
          const size_t v = index(uint32_t(i), uint32_t(j), uint32_t(k));
          const float d = glm::length(glm::vec3(float(i), float(j), float(k)) - g);
          if (d < distance_[v]) {
            distance_[v] = d;
            nearest_[v] = int32_t(p);
          }
        }
  }
  auto relax = [&](int i, int j, int k, int di, int dj, int dk) {
    const int ni = i + di, nj = j + dj, nk = k + dk;
    if (ni < 0 || nj < 0 || nk < 0 || ni >= n || nj >= n || nk >= n) return;
    const int32_t p = nearest_[index(uint32_t(ni), uint32_t(nj), uint32_t(nk))];
    if (p < 0) return;
    const size_t v = index(uint32_t(i), uint32_t(j), uint32_t(k));
    const float d = glm::length(glm::vec3(float(i), float(j), float(k)) - surface_[size_t(p)]);
    if (d < distance_[v]) {
      distance_[v] = d;
      nearest_[v] = p;
    }
  };
  // The 13 neighbours before a node in raster order, and (negated) the 13 after it.
  static constexpr int kBefore[13][3] = {
      {-1, -1, -1}, {0, -1, -1}, {1, -1, -1}, {-1, 0, -1}, {0, 0, -1}, {1, 0, -1}, {-1, 1, -1},
      {0, 1, -1},   {1, 1, -1},  {-1, -1, 0}, {0, -1, 0},  {1, -1, 0}, {-1, 0, 0}};
  if (!surface_.empty()) {
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
          for (const auto& o : kBefore) relax(i, j, k, o[0], o[1], o[2]);
    for (int k = n - 1; k >= 0; --k)
      for (int j = n - 1; j >= 0; --j)
        for (int i = n - 1; i >= 0; --i)
          for (const auto& o : kBefore) relax(i, j, k, -o[0], -o[1], -o[2]);
  }
  if (volume_.origin() != glm::vec3(corner_) * options_.voxel)
    volume_ =
        DistanceVolume(glm::vec3(corner_) * options_.voxel, options_.voxel, glm::uvec3(n_), tau);
  std::span<float> out = volume_.values();
  for (size_t v = 0; v < count; ++v) {
    const float d = std::min(tau, options_.voxel * distance_[v]);
    out[v] = fused(v) < 0.0f ? -d : d;
  }
}

size_t DepthFusion::observedVoxels() const {
  return size_t(std::count_if(weight_.begin(), weight_.end(), [](float w) { return w > 0.0f; }));
}

}  // namespace sdfg
