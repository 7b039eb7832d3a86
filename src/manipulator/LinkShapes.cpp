// The generic drawing of an arm's links from its kinematic parameters (LinkShapes.hpp).
#include "LinkShapes.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace rp::internal {

namespace {

constexpr double kMinLength = 1e-4;  // [m] offsets shorter than this are not drawn

// A cylinder of radius r between points a and b of frame `frame`.
Shape segment(const std::string& frame, const Vector<3>& a, const Vector<3>& b, double r, const Color& color) {
  const Vector<3> d = b - a;
  const double length = d.norm();
  // The shape's z axis along d: any rotation that takes z to d.
  const Vector<3> z{{0.0}, {0.0}, {1.0}};
  const Vector<3> axis = z.cross(d / length);
  const double s = axis.norm(), c = z.dot(d / length);
  Transform pose = translation((a + b) * 0.5);
  if (s > 1e-12) {
    pose = pose * rotation(axis / s, std::atan2(s, c));
  } else if (c < 0) {
    pose = pose * xRotation(M_PI);
  }
  Shape shape;
  shape.kind = ShapeKind::Cylinder;
  shape.frame = frame;
  shape.pose = pose;
  shape.size = Vector<3>{{r}, {length}, {0.0}};
  shape.color = color;
  return shape;
}

// A motor housing on the axis `axis` through point p of frame `frame`.
Shape housing(const std::string& frame, const Vector<3>& p, const Vector<3>& axis, double r, const Color& color) {
  return segment(frame, p - axis * (1.3 * r), p + axis * (1.3 * r), 1.35 * r, color);
}

}  // namespace

void addLinkShapes(const ManipulatorModel& model, Model3D& m) {
  const int n = model.getNumberOfJoints();
  const Color linkColor{0.82, 0.82, 0.78, 1.0};
  const Color motorColor{0.32, 0.34, 0.38, 1.0};
  const Vector<3> origin = Vector<3>::Zero();
  const Vector<3> z{{0.0}, {0.0}, {1.0}};
  // Where joint i+1's frame origin lies in link frame i, and the path there (through the corner
  // between the two offsets), per convention; the first radius from the arm's reach.
  double reach = 0;
  for (int i = 0; i < n; ++i) {
    const LinkParameters& l = model.getLink(i);
    reach += model.getConvention() == DHConvention::Placement
                 ? Vector<3>(model.getPlacement(i).topRightCorner<3, 1>()).norm()
                 : std::abs(l.a) + std::abs(l.d);
  }
  const double r0 = std::clamp(0.055 * reach, 0.015, 0.12);
  auto radius = [&](int i) { return r0 * std::max(0.45, 1.0 - 0.1 * i); };
  auto linkFrame = [](int i) { return "link" + std::to_string(i + 1); };

  switch (model.getConvention()) {
    case DHConvention::Standard: {
      // A_i = Rz(theta) Tz(d) Tx(a) Rx(alpha): in frame i, the previous frame's origin is at
      // (-a, -d sin(alpha), -d cos(alpha)); the joint's axis z_{i-1} points along (0, sin, cos).
      m.shapes.push_back(housing("base", origin, z, radius(0), motorColor));
      for (int i = 0; i < n; ++i) {
        const LinkParameters& l = model.getLink(i);
        const double d = l.type == JointType::Prismatic ? 0.0 : l.d;  // a prismatic offset varies
        const Vector<3> axisPrev{{0.0}, {std::sin(l.alpha)}, {std::cos(l.alpha)}};
        const Vector<3> corner{{-l.a}, {0.0}, {0.0}};
        const Vector<3> start = corner - axisPrev * d;
        if (std::abs(d) > kMinLength) m.shapes.push_back(segment(linkFrame(i), start, corner, radius(i), linkColor));
        if (std::abs(l.a) > kMinLength) m.shapes.push_back(segment(linkFrame(i), corner, origin, radius(i), linkColor));
        if (i + 1 < n) m.shapes.push_back(housing(linkFrame(i), origin, z, radius(i + 1), motorColor));
      }
      break;
    }
    case DHConvention::Modified:
    case DHConvention::Placement: {
      // Frame i sits on joint i's axis (z_i); link i reaches joint i+1's frame: for modified DH
      // along x_i by a_i then along z_{i+1} by d_{i+1}; for placements straight to its origin.
      for (int i = 0; i < n; ++i) {
        m.shapes.push_back(housing(linkFrame(i), origin, z, radius(i), motorColor));
        if (i + 1 >= n) break;
        const LinkParameters& next = model.getLink(i + 1);
        if (model.getConvention() == DHConvention::Modified) {
          const double d = next.type == JointType::Prismatic ? 0.0 : next.d;
          const Vector<3> corner{{next.a}, {0.0}, {0.0}};
          const Vector<3> end = corner + Vector<3>{{0.0}, {-std::sin(next.alpha)}, {std::cos(next.alpha)}} * d;
          if (std::abs(next.a) > kMinLength) m.shapes.push_back(segment(linkFrame(i), origin, corner, radius(i), linkColor));
          if (std::abs(d) > kMinLength) m.shapes.push_back(segment(linkFrame(i), corner, end, radius(i), linkColor));
        } else {
          const Vector<3> end = model.getPlacement(i + 1).topRightCorner<3, 1>();
          if (end.norm() > kMinLength) m.shapes.push_back(segment(linkFrame(i), origin, end, radius(i), linkColor));
        }
      }
      break;
    }
  }
  // The flange at the last link frame, and a short stub to the tool frame.
  const double rf = radius(n);
  m.shapes.push_back(segment(linkFrame(n - 1), origin, z * (0.6 * rf), 1.1 * rf, motorColor));
  const Vector<3> tool = model.getToolTransform().topRightCorner<3, 1>();
  if (tool.norm() > kMinLength) m.shapes.push_back(segment(linkFrame(n - 1), origin, tool, 0.5 * rf, linkColor));
  m.linksDrawn = true;
}

}  // namespace rp::internal
