#include "quadric_slam/sim/surfaces.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace quadric_slam {
namespace {

constexpr double kParallel = 1e-12;

// Roots of a t^2 + 2 b t + c = 0 in increasing order; false when none are real.
bool solveQuadratic(double a, double b, double c, double* t0, double* t1) {
  if (std::abs(a) < kParallel) {
    if (std::abs(b) < kParallel)
      return false;
    *t0 = *t1 = -c / (2.0 * b);
    return true;
  }
  const double disc = b * b - a * c;
  if (disc < 0.0)
    return false;
  const double root = std::sqrt(disc);
  // Numerically stable form.
  const double q = -(b + std::copysign(root, b));
  double r0 = q / a, r1 = (std::abs(q) > 0.0) ? c / q : -b / a;
  if (r0 > r1)
    std::swap(r0, r1);
  *t0 = r0;
  *t1 = r1;
  return true;
}

// Lattice cells between the texture slices of consecutive surface ids: more than any surface
// spans in texture cells along its local x, so no two surfaces share lattice values.
constexpr int kTextureSliceSpacing = 10007;

std::uint32_t hash3(int x, int y, int z) {
  std::uint32_t h = static_cast<std::uint32_t>(x) * 73856093u ^
                    static_cast<std::uint32_t>(y) * 19349663u ^
                    static_cast<std::uint32_t>(z) * 83492791u;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return h;
}

double lattice(int x, int y, int z) {
  return (hash3(x, y, z) & 0xffffu) * (1.0 / 65535.0);
}

// Smooth value noise in [0, 1] (trilinear interpolation of lattice values with smoothstep).
double valueNoise(const Eigen::Vector3d& p) {
  const int x0 = static_cast<int>(std::floor(p.x())), y0 = static_cast<int>(std::floor(p.y())),
            z0 = static_cast<int>(std::floor(p.z()));
  auto smooth = [](double f) { return f * f * (3.0 - 2.0 * f); };
  const double fx = smooth(p.x() - x0), fy = smooth(p.y() - y0), fz = smooth(p.z() - z0);
  double result = 0.0;
  for (int dz = 0; dz <= 1; ++dz)
    for (int dy = 0; dy <= 1; ++dy)
      for (int dx = 0; dx <= 1; ++dx) {
        const double w = (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) * (dz ? fz : 1 - fz);
        result += w * lattice(x0 + dx, y0 + dy, z0 + dz);
      }
  return result;
}

// The same on the lattice plane x = slice (planar surfaces): four lattice values instead of eight.
double valueNoise2d(int slice, double y, double z) {
  const int y0 = static_cast<int>(std::floor(y)), z0 = static_cast<int>(std::floor(z));
  auto smooth = [](double f) { return f * f * (3.0 - 2.0 * f); };
  const double fy = smooth(y - y0), fz = smooth(z - z0);
  const double a = lattice(slice, y0, z0), b = lattice(slice, y0 + 1, z0);
  const double c = lattice(slice, y0, z0 + 1), d = lattice(slice, y0 + 1, z0 + 1);
  return (1 - fz) * ((1 - fy) * a + fy * b) + fz * ((1 - fy) * c + fy * d);
}

Eigen::Isometry3d offsetPose(const Eigen::Isometry3d& parent, const Eigen::Matrix3d& rotation,
                             const Eigen::Vector3d& translation) {
  Eigen::Isometry3d local = Eigen::Isometry3d::Identity();
  local.linear() = rotation;
  local.translation() = translation;
  return parent * local;
}

Eigen::Matrix3d rotZ(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).matrix();
}
Eigen::Matrix3d rotY(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).matrix();
}

}  // namespace

Surface::Surface(int id, std::string name, SurfaceKind kind,
                 const Eigen::Isometry3d& T_world_surface, const Eigen::Vector3d& dims,
                 const Material& material, bool closed_face)
    : id_(id),
      name_(std::move(name)),
      kind_(kind),
      T_world_surface_(T_world_surface),
      T_surface_world_(T_world_surface.inverse()),
      dims_(dims),
      material_(material),
      closed_face_(closed_face) {
  Eigen::Vector3d centre_local = Eigen::Vector3d::Zero();
  switch (kind_) {
    case SurfaceKind::kRectangle:
      bound_radius_ = std::hypot(dims_.y(), dims_.z());
      break;
    case SurfaceKind::kDisc:
      bound_radius_ = dims_.y();
      break;
    case SurfaceKind::kSphere:
    case SurfaceKind::kEllipsoid:
      bound_radius_ = dims_.maxCoeff();
      break;
    case SurfaceKind::kCylinder:
      bound_radius_ = std::hypot(dims_.x(), dims_.z());
      break;
    case SurfaceKind::kCone:
      centre_local.z() = 0.5 * (dims_.y() + dims_.z());
      bound_radius_ = std::hypot(0.5 * (dims_.z() - dims_.y()), dims_.x() * dims_.z());
      break;
  }
  bound_centre_ = T_world_surface_ * centre_local;
}

bool Surface::mayBeVisibleFrom(const Eigen::Vector3d& viewpoint) const {
  if (!closed_face_)
    return true;
  return T_world_surface_.linear().col(0).dot(viewpoint - T_world_surface_.translation()) > 0.0;
}

bool Surface::intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                        double t_min, double t_max, double* t, Eigen::Vector3d* normal_world,
                        Eigen::Vector3d* point_local) const {
  const Eigen::Vector3d o = T_surface_world_ * origin;
  const Eigen::Vector3d d = T_surface_world_.linear() * direction;
  if (!intersectLocal(o, d, t_min, t_max, t))
    return false;
  const Eigen::Vector3d p = o + *t * d;
  if (normal_world)
    *normal_world = (T_world_surface_.linear() * normalLocal(p)).normalized();
  if (point_local)
    *point_local = p;
  return true;
}

Eigen::Vector3d Surface::normalLocal(const Eigen::Vector3d& p) const {
  switch (kind_) {
    case SurfaceKind::kRectangle:
    case SurfaceKind::kDisc:
      return Eigen::Vector3d::UnitX();
    case SurfaceKind::kSphere:
    case SurfaceKind::kEllipsoid:
      return p.cwiseQuotient(dims_.cwiseProduct(dims_));
    case SurfaceKind::kCylinder:
      return Eigen::Vector3d(p.x(), p.y(), 0.0);
    case SurfaceKind::kCone:
      return Eigen::Vector3d(p.x(), p.y(), -dims_.x() * dims_.x() * p.z());
  }
  return Eigen::Vector3d::UnitX();
}

bool Surface::intersectLocal(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min,
                             double t_max, double* t) const {
  switch (kind_) {
    case SurfaceKind::kRectangle:
    case SurfaceKind::kDisc: {
      if (std::abs(d.x()) < kParallel)
        return false;
      const double tt = -o.x() / d.x();
      if (!(tt > t_min && tt < t_max))
        return false;
      const double y = o.y() + tt * d.y(), z = o.z() + tt * d.z();
      const bool inside = kind_ == SurfaceKind::kRectangle
                              ? (std::abs(y) <= dims_.y() && std::abs(z) <= dims_.z())
                              : (y * y + z * z <= dims_.y() * dims_.y());
      if (!inside)
        return false;
      *t = tt;
      return true;
    }
    case SurfaceKind::kSphere:
    case SurfaceKind::kEllipsoid: {
      // Scale to the unit sphere: |o' + t d'|^2 = 1 with o' = o / radii, d' = d / radii.
      const Eigen::Vector3d os = o.cwiseQuotient(dims_), ds = d.cwiseQuotient(dims_);
      double t0, t1;
      if (!solveQuadratic(ds.squaredNorm(), os.dot(ds), os.squaredNorm() - 1.0, &t0, &t1))
        return false;
      for (double tt : {t0, t1}) {
        if (tt > t_min && tt < t_max) {
          *t = tt;
          return true;
        }
      }
      return false;
    }
    case SurfaceKind::kCylinder: {
      const double r = dims_.x(), h = dims_.z();
      double t0, t1;
      if (!solveQuadratic(d.x() * d.x() + d.y() * d.y(), o.x() * d.x() + o.y() * d.y(),
                          o.x() * o.x() + o.y() * o.y() - r * r, &t0, &t1))
        return false;
      for (double tt : {t0, t1}) {
        if (!(tt > t_min && tt < t_max))
          continue;
        const Eigen::Vector3d p = o + tt * d;
        if (std::abs(p.z()) > h)
          continue;
        *t = tt;
        return true;
      }
      return false;
    }
    case SurfaceKind::kCone: {
      // x^2 + y^2 = k z^2 with k = tan^2(half angle), z in [z_min, z_max].
      const double k = dims_.x() * dims_.x();
      double t0, t1;
      if (!solveQuadratic(d.x() * d.x() + d.y() * d.y() - k * d.z() * d.z(),
                          o.x() * d.x() + o.y() * d.y() - k * o.z() * d.z(),
                          o.x() * o.x() + o.y() * o.y() - k * o.z() * o.z(), &t0, &t1))
        return false;
      for (double tt : {t0, t1}) {
        if (!(tt > t_min && tt < t_max))
          continue;
        const Eigen::Vector3d p = o + tt * d;
        if (p.z() < dims_.y() || p.z() > dims_.z())
          continue;
        *t = tt;
        return true;
      }
      return false;
    }
  }
  return false;
}

Eigen::Vector3d Surface::albedo(const Eigen::Vector3d& point_local) const {
  if (material_.texture == Texture::kNone)
    return material_.colour;
  Eigen::Vector3d p = point_local * (1.0 / material_.texture_scale);
  const bool planar = kind_ == SurfaceKind::kRectangle || kind_ == SurfaceKind::kDisc;
  if (planar)
    p.x() = 0.5;  // in-plane pattern, away from a lattice boundary
  if (material_.texture == Texture::kChecker) {
    const long parity = static_cast<long>(std::floor(p.x())) +
                        static_cast<long>(std::floor(p.y())) + static_cast<long>(std::floor(p.z()));
    return (parity & 1) ? material_.colour2 : material_.colour;
  }
  // Each surface reads its own part of the noise lattice (by its id): two walls of one material
  // do not carry the same pattern, which no real room does and which image corners would match
  // from one wall to the other.
  const int slice = kTextureSliceSpacing * id_;
  p.x() += slice;
  // Smooth value noise plus a fine, uninterpolated grain (one hash) at a quarter of the cell.
  const Eigen::Vector3d fine = 4.0 * p;
  const double grain =
      lattice(static_cast<int>(std::floor(fine.x())), static_cast<int>(std::floor(fine.y())),
              static_cast<int>(std::floor(fine.z())));
  const double smooth = planar ? valueNoise2d(slice, p.y(), p.z()) : valueNoise(p);
  const double w = 0.75 * smooth + 0.25 * grain;
  return (1.0 - w) * material_.colour + w * material_.colour2;
}

MapFileQuadric Surface::toMapQuadric() const {
  MapFileQuadric q;
  q.id = id_;
  q.T_map_quadric = T_world_surface_;
  const Eigen::Vector3d t = T_world_surface_.translation();
  const Eigen::Matrix3d R = T_world_surface_.linear();
  auto vec = [](const Eigen::Vector3d& v) { return std::vector<double>{v.x(), v.y(), v.z()}; };
  switch (kind_) {
    case SurfaceKind::kRectangle:
    case SurfaceKind::kDisc:
      q.quadric_class = "plane";
      q.scale = Eigen::Vector3d::Ones();
      q.shape["normal"] = vec(R.col(0));
      q.shape["offset"] = {R.col(0).dot(t)};
      break;
    case SurfaceKind::kSphere:
      q.quadric_class = "sphere";
      q.scale = Eigen::Vector3d::Constant(1.0 / dims_.x());
      q.shape["center"] = vec(t);
      q.shape["radius"] = {dims_.x()};
      break;
    case SurfaceKind::kCylinder:
      q.quadric_class = "cylinder";
      q.scale = Eigen::Vector3d(1.0 / dims_.x(), 1.0 / dims_.x(), 1.0);
      q.shape["point"] = vec(t);
      q.shape["axis"] = vec(R.col(2));
      q.shape["radius"] = {dims_.x()};
      break;
    case SurfaceKind::kCone:
      q.quadric_class = "cone";
      q.scale = Eigen::Vector3d(1.0 / dims_.x(), 1.0 / dims_.x(), 1.0);
      q.shape["apex"] = vec(t);
      q.shape["axis"] = vec(R.col(2));
      q.shape["half_angle"] = {std::atan(dims_.x())};
      break;
    case SurfaceKind::kEllipsoid:
      q.quadric_class = "ellipsoid";
      q.scale = dims_.cwiseInverse();
      q.shape["center"] = vec(t);
      q.shape["radii"] = vec(dims_);
      break;
  }
  // The bounded piece, in the surface frame (the quadric's): see the dims convention in the header.
  q.has_extent = true;
  switch (kind_) {
    case SurfaceKind::kRectangle:
      q.extent_max = Eigen::Vector3d(0.0, dims_.y(), dims_.z());
      break;
    case SurfaceKind::kDisc:
      q.extent_max = Eigen::Vector3d(0.0, dims_.y(), dims_.y());
      break;
    case SurfaceKind::kCone: {
      const double rim = std::max(std::abs(dims_.y()), std::abs(dims_.z())) * dims_.x();
      q.extent_min = Eigen::Vector3d(-rim, -rim, dims_.y());
      q.extent_max = Eigen::Vector3d(rim, rim, dims_.z());
      return q;
    }
    case SurfaceKind::kSphere:
    case SurfaceKind::kCylinder:
    case SurfaceKind::kEllipsoid:
      q.extent_max = dims_;
      break;
  }
  q.extent_min = -q.extent_max;
  return q;
}

std::vector<Surface> buildSurfaces(const Scene& scene) {
  std::vector<Surface> surfaces;
  int next_id = 1;
  auto add = [&](const std::string& name, SurfaceKind kind, const Eigen::Isometry3d& pose,
                 const Eigen::Vector3d& dims, const Material& material, bool closed_face = false) {
    surfaces.emplace_back(next_id++, name, kind, pose, dims, material, closed_face);
  };
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  for (const PrimitiveSpec& p : scene.primitives) {
    const std::string problem = p.problem();
    if (!problem.empty())
      throw std::invalid_argument("primitive '" + p.name + "': " + problem);
    const Eigen::Isometry3d& T = p.T_world_primitive;
    switch (p.type) {
      case PrimitiveType::kRectangle:
        add(p.name, SurfaceKind::kRectangle, T, Eigen::Vector3d(0, p.size.y() / 2, p.size.z() / 2),
            p.material);
        break;
      case PrimitiveType::kBox: {
        const Eigen::Vector3d h = p.size / 2;
        add(p.name + "/+x", SurfaceKind::kRectangle, offsetPose(T, I, {h.x(), 0, 0}),
            {0, h.y(), h.z()}, p.material, true);
        add(p.name + "/-x", SurfaceKind::kRectangle, offsetPose(T, rotZ(M_PI), {-h.x(), 0, 0}),
            {0, h.y(), h.z()}, p.material, true);
        add(p.name + "/+y", SurfaceKind::kRectangle, offsetPose(T, rotZ(M_PI / 2), {0, h.y(), 0}),
            {0, h.x(), h.z()}, p.material, true);
        add(p.name + "/-y", SurfaceKind::kRectangle, offsetPose(T, rotZ(-M_PI / 2), {0, -h.y(), 0}),
            {0, h.x(), h.z()}, p.material, true);
        add(p.name + "/+z", SurfaceKind::kRectangle, offsetPose(T, rotY(-M_PI / 2), {0, 0, h.z()}),
            {0, h.y(), h.x()}, p.material, true);
        add(p.name + "/-z", SurfaceKind::kRectangle, offsetPose(T, rotY(M_PI / 2), {0, 0, -h.z()}),
            {0, h.y(), h.x()}, p.material, true);
        break;
      }
      case PrimitiveType::kSphere:
        add(p.name, SurfaceKind::kSphere, T, Eigen::Vector3d::Constant(p.radius), p.material);
        break;
      case PrimitiveType::kCylinder:
        add(p.name, SurfaceKind::kCylinder, T, {p.radius, p.radius, p.length / 2}, p.material);
        if (p.capped) {
          add(p.name + "/+z", SurfaceKind::kDisc,
              offsetPose(T, rotY(-M_PI / 2), {0, 0, p.length / 2}), {0, p.radius, 0}, p.material,
              true);
          add(p.name + "/-z", SurfaceKind::kDisc,
              offsetPose(T, rotY(M_PI / 2), {0, 0, -p.length / 2}), {0, p.radius, 0}, p.material,
              true);
        }
        break;
      case PrimitiveType::kCone:
        add(p.name, SurfaceKind::kCone, T, {std::tan(p.half_angle), p.z_min, p.z_max}, p.material);
        break;
      case PrimitiveType::kEllipsoid:
        add(p.name, SurfaceKind::kEllipsoid, T, p.radii, p.material);
        break;
    }
  }
  return surfaces;
}

std::string toString(PrimitiveType type) {
  switch (type) {
    case PrimitiveType::kRectangle:
      return "rectangle";
    case PrimitiveType::kBox:
      return "box";
    case PrimitiveType::kSphere:
      return "sphere";
    case PrimitiveType::kCylinder:
      return "cylinder";
    case PrimitiveType::kCone:
      return "cone";
    case PrimitiveType::kEllipsoid:
      return "ellipsoid";
  }
  return "unknown";
}

PrimitiveType primitiveTypeFromString(const std::string& name) {
  for (PrimitiveType type :
       {PrimitiveType::kRectangle, PrimitiveType::kBox, PrimitiveType::kSphere,
        PrimitiveType::kCylinder, PrimitiveType::kCone, PrimitiveType::kEllipsoid}) {
    if (toString(type) == name)
      return type;
  }
  throw std::invalid_argument("unknown primitive type '" + name +
                              "' (rectangle, box, sphere, cylinder, cone, ellipsoid)");
}

std::string PrimitiveSpec::problem() const {
  auto positive = [](const Eigen::Vector3d& v) { return (v.array() > 0.0).all() && v.allFinite(); };
  switch (type) {
    case PrimitiveType::kRectangle:
      if (!(size.y() > 0.0 && size.z() > 0.0))
        return "size (y, z) must be > 0 m";
      break;
    case PrimitiveType::kBox:
      if (!positive(size))
        return "size must be > 0 m";
      break;
    case PrimitiveType::kSphere:
      if (!(radius > 0.0))
        return "radius must be > 0 m";
      break;
    case PrimitiveType::kCylinder:
      if (!(radius > 0.0))
        return "radius must be > 0 m";
      if (!(length > 0.0))
        return "length must be > 0 m";
      break;
    case PrimitiveType::kCone:
      if (!(half_angle > 0.0 && half_angle < M_PI / 2))
        return "half_angle must be in (0, pi/2) rad";
      if (!(z_min >= 0.0 && z_max > z_min))
        return "z_min, z_max must satisfy 0 <= z_min < z_max (m)";
      break;
    case PrimitiveType::kEllipsoid:
      if (!positive(radii))
        return "radii must be > 0 m";
      break;
  }
  const Eigen::Vector3d c = material.colour, c2 = material.colour2;
  if ((c.array() < 0).any() || (c.array() > 1).any() || (c2.array() < 0).any() ||
      (c2.array() > 1).any())
    return "colours must be in [0, 1]";
  if (!(material.texture_scale > 0.0))
    return "texture_scale must be > 0 m";
  return "";
}

}  // namespace quadric_slam
