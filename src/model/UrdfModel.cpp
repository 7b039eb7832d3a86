// Loading manipulator models from URDF (rp/model/UrdfModel.hpp).
#include "rp/model/UrdfModel.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <tinyxml.h>
#include <unistd.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <numbers>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "rp/model/Kinematics.hpp"

namespace rp {

namespace {

using V3 = Eigen::Vector3d;

constexpr std::size_t kMaxUrdfBytes = std::size_t{64} << 20;  // largest URDF file read
constexpr std::size_t kMaxUrdfDepth = 100;                     // deepest element nesting accepted

Transform toTransform(const urdf::Pose& p) {
  Transform t = Transform::unit();
  t.topLeftCorner<3, 3>() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z).toRotationMatrix();
  t(0, 3) = p.position.x;
  t(1, 3) = p.position.y;
  t(2, 3) = p.position.z;
  return t;
}

// A rigid body accumulated in root coordinates (at q = 0).
struct Body {
  double mass = 0;
  V3 moment = V3::Zero();           // sum of m c
  Eigen::Matrix3d inertiaAtOrigin;  // sum of I_c + m (|c|^2 1 - c c^T), about the root origin
  bool any = false;
  Body() { inertiaAtOrigin.setZero(); }
  void add(double m, const V3& c, const Eigen::Matrix3d& Ic) {
    mass += m;
    moment += m * c;
    inertiaAtOrigin += Ic + m * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
    any = true;
  }
};

struct Line {
  V3 point, direction;
};

// The DH frame whose z is `axis` and whose origin lies on it, with x along the common normal
// from the previous frame's z axis (or a free perpendicular).
Transform frame(const V3& origin, const V3& z, const V3& x) {
  Transform f = Transform::unit();
  f.block<3, 1>(0, 0) = x;
  f.block<3, 1>(0, 1) = z.cross(x);
  f.block<3, 1>(0, 2) = z;
  f.topRightCorner<3, 1>() = origin;
  return f;
}

V3 anyPerpendicular(const V3& z) {
  const V3 trial = std::abs(z.x()) < 0.9 ? V3::UnitX() : V3::UnitY();
  return (trial - trial.dot(z) * z).normalized();
}

// At most this much of a name is quoted in a message.
std::string excerpt(const std::string& text) {
  constexpr std::size_t kMax = 40;
  if (text.size() <= kMax) return text;
  std::size_t n = kMax - 3;
  while (n > 0 && (static_cast<unsigned char>(text[n]) & 0xC0) == 0x80) --n;  // whole UTF-8 characters
  return text.substr(0, n) + "...";
}

// The file's text: a regular file of at most kMaxUrdfBytes (a device such as /dev/zero or a FIFO
// is refused before it is opened).
std::string readUrdfFile(const std::string& fileName) {
  struct stat st {};
  if (::stat(fileName.c_str(), &st) != 0) throw UrdfError(fileName + ": cannot read the file");
  if (!S_ISREG(st.st_mode)) throw UrdfError(fileName + ": cannot read the file: it is not a regular file");
  const int fd = ::open(fileName.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) throw UrdfError(fileName + ": cannot read the file");
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  const std::string tooLarge = fileName + ": the file is larger than " + std::to_string(kMaxUrdfBytes >> 20) + " MiB";
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
    throw UrdfError(fileName + ": cannot read the file: it is not a regular file");
  if (st.st_size > static_cast<off_t>(kMaxUrdfBytes)) throw UrdfError(tooLarge);
  std::string text;
  char buffer[65536];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw UrdfError(fileName + ": cannot read the file: " + std::strerror(errno));
    if (n == 0) break;
    if (text.size() + static_cast<std::size_t>(n) > kMaxUrdfBytes) throw UrdfError(tooLarge);
    text.append(buffer, static_cast<std::size_t>(n));
  }
  return text;
}

// Refuses XML whose elements nest deeper than kMaxUrdfDepth: the XML parser recurses once per
// level, so a deep enough document would overflow the stack. Counts start and end tags, skipping
// comments, CDATA, processing instructions, declarations and quoted attribute values.
void checkNesting(const std::string& text, const std::string& fileName) {
  std::size_t depth = 0;
  std::size_t i = 0;
  auto skipPast = [&](const char* end) {
    const std::size_t at = text.find(end, i);
    i = at == std::string::npos ? text.size() : at + std::strlen(end);
  };
  while ((i = text.find('<', i)) != std::string::npos) {
    if (text.compare(i, 4, "<!--") == 0) {
      skipPast("-->");
    } else if (text.compare(i, 9, "<![CDATA[") == 0) {
      skipPast("]]>");
    } else if (text.compare(i, 2, "<?") == 0) {
      skipPast("?>");
    } else if (text.compare(i, 2, "<!") == 0 || text.compare(i, 2, "</") == 0) {
      if (text[i + 1] == '/' && depth > 0) --depth;
      skipPast(">");
    } else {
      // A start tag: find its '>' outside quotes; "/>" closes it at once.
      char quote = 0;
      std::size_t j = i + 1;
      for (; j < text.size(); ++j) {
        const char c = text[j];
        if (quote) {
          if (c == quote) quote = 0;
        } else if (c == '"' || c == '\'') {
          quote = c;
        } else if (c == '>') {
          break;
        }
      }
      if (j >= text.size()) return;  // unterminated: the parser reports it
      if (text[j - 1] != '/' && ++depth > kMaxUrdfDepth)
        throw UrdfError(fileName + ": elements nest deeper than " + std::to_string(kMaxUrdfDepth) + " levels");
      i = j + 1;
    }
  }
}

// Parses an attribute as a finite number; false if it is missing or not one.
bool finiteAttribute(const TiXmlElement* e, const char* name, double& value) {
  const char* text = e ? e->Attribute(name) : nullptr;
  if (!text) return false;
  std::string t(text);
  const auto b = t.find_first_not_of(" \t\r\n"), last = t.find_last_not_of(" \t\r\n");
  if (b == std::string::npos) return false;
  t = t.substr(b, last - b + 1);
  const char* begin = t.data() + (t[0] == '+' ? 1 : 0);
  const auto [ptr, ec] = std::from_chars(begin, t.data() + t.size(), value);
  return ec == std::errc() && ptr == t.data() + t.size() && std::isfinite(value);
}

// An optional attribute of three numbers ("x y z"): absent, or three finite numbers.
bool finiteTriple(const TiXmlElement* e, const char* name) {
  const char* text = e ? e->Attribute(name) : nullptr;
  if (!text) return true;
  const std::string t(text);
  int count = 0;
  std::size_t i = 0;
  while (true) {
    i = t.find_first_not_of(" \t\r\n", i);
    if (i == std::string::npos) break;
    const std::size_t end = std::min(t.find_first_of(" \t\r\n", i), t.size());
    const char* begin = t.data() + i + (t[i] == '+' ? 1 : 0);
    double v = 0;
    const auto [ptr, ec] = std::from_chars(begin, t.data() + end, v);
    if (ec != std::errc() || ptr != t.data() + end || !std::isfinite(v)) return false;
    ++count;
    i = end;
  }
  return count == 3;
}

// Checks every link's <inertial> in the XML itself: urdfdom drops an inertial it cannot parse
// (mass="nan", a missing inertia attribute) with a message on stderr and loads a massless link.
void checkInertials(const TiXmlElement* robot, const std::string& fileName) {
  for (const TiXmlElement* link = robot->FirstChildElement("link"); link; link = link->NextSiblingElement("link")) {
    const TiXmlElement* inertial = link->FirstChildElement("inertial");
    if (!inertial) continue;
    const char* nameAttribute = link->Attribute("name");
    const std::string where = fileName + ": link '" + excerpt(nameAttribute ? nameAttribute : "") + "': <inertial> ";
    auto quoted = [](const TiXmlElement* e, const char* name) {
      const char* v = e ? e->Attribute(name) : nullptr;
      if (!v) return std::string("missing");
      std::string q(1, '\'');  // appended piece by piece: GCC 12 warns (-Wrestrict) about "'" + s
      q += excerpt(v);
      q += '\'';
      return q;
    };
    const TiXmlElement* origin = inertial->FirstChildElement("origin");
    for (const char* name : {"xyz", "rpy"})
      if (!finiteTriple(origin, name))
        throw UrdfError(where + "origin " + name + " " + quoted(origin, name) + " is not three finite numbers");
    const TiXmlElement* mass = inertial->FirstChildElement("mass");
    double m = 0;
    if (!finiteAttribute(mass, "value", m))
      throw UrdfError(where + "mass value is not a finite number (" + quoted(mass, "value") + ")");
    if (m < 0) throw UrdfError(where + "mass " + quoted(mass, "value") + " is negative");
    const TiXmlElement* inertia = inertial->FirstChildElement("inertia");
    for (const char* name : {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"}) {
      double v = 0;
      if (!finiteAttribute(inertia, name, v))
        throw UrdfError(where + "inertia " + name + " is not a finite number (" + quoted(inertia, name) + ")");
    }
  }
}

constexpr const char* kLoop = ": a kinematic loop; a manipulator's links must form a tree";

// Checks in the XML that the joints link the links into one tree, before urdfdom builds it:
// urdfdom accepts a kinematic loop (and walking it never ends), and when it fails half-way
// (a second root, a joint naming an unknown link) it leaks a loop's links and frees a long chain
// with one recursive call per link.
void checkJointGraph(const TiXmlElement* robot, const std::string& fileName) {
  std::vector<std::string> links;  // in file order
  std::unordered_set<std::string> defined;
  for (const TiXmlElement* link = robot->FirstChildElement("link"); link; link = link->NextSiblingElement("link")) {
    const char* name = link->Attribute("name");
    if (name && defined.insert(name).second) links.emplace_back(name);
  }
  std::unordered_map<std::string, std::pair<std::string, std::string>> parentOf;  // link -> (parent link, joint)
  for (const TiXmlElement* joint = robot->FirstChildElement("joint"); joint; joint = joint->NextSiblingElement("joint")) {
    const char* nameAttribute = joint->Attribute("name");
    const std::string name = nameAttribute ? nameAttribute : "";
    const TiXmlElement* parentElement = joint->FirstChildElement("parent");
    const TiXmlElement* childElement = joint->FirstChildElement("child");
    const char* parent = parentElement ? parentElement->Attribute("link") : nullptr;
    const char* child = childElement ? childElement->Attribute("link") : nullptr;
    const std::string where = fileName + ": joint '" + excerpt(name) + "'";
    if (!parent || !*parent) throw UrdfError(where + " has no parent link");
    if (!child || !*child) throw UrdfError(where + " has no child link");
    for (const char* link : {parent, child})
      if (!defined.count(link)) throw UrdfError(where + ": there is no link '" + excerpt(link) + "'");
    const auto [it, added] = parentOf.emplace(child, std::make_pair(std::string(parent), name));
    if (!added)
      throw UrdfError(fileName + ": link '" + excerpt(child) + "' is the child of two joints ('" +
                      excerpt(it->second.second) + "' and '" + excerpt(name) + "')" + kLoop);
  }
  std::vector<const std::string*> roots;
  for (const std::string& link : links)
    if (!parentOf.count(link)) roots.push_back(&link);
  if (roots.empty() && !links.empty())
    throw UrdfError(fileName + ": there is no root link (every link is the child of a joint)" + kLoop);
  if (roots.size() > 1)
    throw UrdfError(fileName + ": links '" + excerpt(*roots[0]) + "' and '" + excerpt(*roots[1]) +
                    "' both have no parent joint; a robot has one root link");
  // Every link must reach the root through its parents; a walk that comes back to a link of its
  // own is a loop. Links found to reach the root are remembered, so each link is walked once.
  std::unordered_set<std::string> reachesRoot;
  if (!roots.empty()) reachesRoot.insert(*roots[0]);
  std::unordered_set<std::string> walk;
  for (const std::string& start : links) {
    walk.clear();
    std::string link = start;
    while (!reachesRoot.count(link)) {
      if (!walk.insert(link).second)
        throw UrdfError(fileName + ": link '" + excerpt(start) + "' cannot be reached from the root link '" +
                        excerpt(*roots[0]) + "'" + kLoop);
      link = parentOf.at(link).first;
    }
    reachesRoot.insert(walk.begin(), walk.end());
  }
}

// The checks that need the XML itself (see checkInertials() and checkJointGraph()).
void checkDocument(const std::string& text, const std::string& fileName) {
  TiXmlDocument doc;
  doc.Parse(text.c_str());
  if (doc.Error()) return;  // urdfdom reports malformed XML
  const TiXmlElement* robot = doc.FirstChildElement("robot");
  if (!robot) return;  // and a missing <robot>
  checkInertials(robot, fileName);
  checkJointGraph(robot, fileName);
}

// The same for the model urdfdom built (a second line of defence: urdfdom might read the XML
// differently): one tree under the root.
void checkTree(const urdf::ModelInterface& robot, const urdf::Link& root, const std::string& fileName) {
  std::map<std::string, std::string> parentJoint;  // child link -> joint
  for (const auto& [name, joint] : robot.joints_) {
    if (!joint) continue;
    const auto [it, added] = parentJoint.emplace(joint->child_link_name, name);
    if (!added)
      throw UrdfError(fileName + ": link '" + excerpt(joint->child_link_name) + "' is the child of two joints ('" +
                      excerpt(it->second) + "' and '" + excerpt(name) + "')" + kLoop);
  }
  std::unordered_set<const urdf::Link*> seen{&root};
  std::vector<const urdf::Link*> todo{&root};
  while (!todo.empty()) {
    const urdf::Link* link = todo.back();
    todo.pop_back();
    for (const urdf::LinkSharedPtr& child : link->child_links)
      if (child && seen.insert(child.get()).second) todo.push_back(child.get());
  }
  for (const auto& [name, link] : robot.links_)
    if (link && !seen.count(link.get()))
      throw UrdfError(fileName + ": link '" + excerpt(name) + "' cannot be reached from the root link '" +
                      excerpt(root.name) + "'" + kLoop);
}

// Whether every number of a pose is finite.
bool finite(const urdf::Pose& p) {
  return std::isfinite(p.position.x) && std::isfinite(p.position.y) && std::isfinite(p.position.z) &&
         std::isfinite(p.rotation.x) && std::isfinite(p.rotation.y) && std::isfinite(p.rotation.z) &&
         std::isfinite(p.rotation.w);
}

// urdfdom links children with shared pointers: a long chain would be freed by one recursive
// destructor call per link (a stack overflow for 100,000 links) and a loop would never be freed.
// Dropping those pointers first leaves each link to be freed alone by the model's own maps.
struct UnlinkOnExit {
  urdf::ModelInterface& robot;
  ~UnlinkOnExit() {
    for (auto& [name, link] : robot.links_)
      if (link) link->child_links.clear();
  }
};

}  // namespace

std::unique_ptr<ManipulatorModel> loadUrdf(const std::string& fileName, const UrdfOptions& options) {
  const std::string text = readUrdfFile(fileName);
  checkNesting(text, fileName);
  checkDocument(text, fileName);
  const urdf::ModelInterfaceSharedPtr robot = urdf::parseURDF(text);
  if (!robot) throw UrdfError(fileName + ": not a valid URDF document (malformed XML or URDF structure)");
  const UnlinkOnExit unlink{*robot};
  const urdf::LinkConstSharedPtr root = robot->getRoot();
  if (!root) throw UrdfError(fileName + ": the robot has no root link");
  checkTree(*robot, *root, fileName);

  // The chain of joints from the root to the tip.
  urdf::LinkConstSharedPtr tip;
  if (!options.tip.empty()) {
    tip = robot->getLink(options.tip);
    if (!tip) throw UrdfError(fileName + ": there is no link '" + options.tip + "'");
  } else {
    urdf::LinkConstSharedPtr link = root, lastMovable;
    while (!link->child_joints.empty()) {
      if (link->child_joints.size() > 1) {
        throw UrdfError(fileName + ": the robot branches at link '" + link->name + "'; name the tip link");
      }
      const urdf::JointConstSharedPtr j = link->child_joints.front();
      link = robot->getLink(j->child_link_name);
      if (j->type == urdf::Joint::REVOLUTE || j->type == urdf::Joint::CONTINUOUS || j->type == urdf::Joint::PRISMATIC) {
        lastMovable = link;
      }
    }
    tip = lastMovable ? lastMovable : link;
  }
  std::vector<urdf::JointConstSharedPtr> chain;
  for (urdf::LinkConstSharedPtr link = tip; link->parent_joint; link = robot->getLink(link->parent_joint->parent_link_name)) {
    chain.push_back(link->parent_joint);
  }
  std::reverse(chain.begin(), chain.end());

  // Poses at q = 0 in root coordinates; movable joints' lines; bodies per movable joint.
  std::vector<Line> axes;
  std::vector<urdf::JointConstSharedPtr> movable;
  std::vector<Body> bodies;
  Transform linkPose = Transform::unit();
  std::unordered_set<std::string> chainLinks;
  for (const urdf::JointConstSharedPtr& j : chain) chainLinks.insert(j->child_link_name);
  // A link's inertia and that of everything fixed to it off the chain (e.g. a camera), walked
  // with an explicit stack: a chain of many fixed links must not recurse once per link.
  std::vector<std::pair<urdf::LinkConstSharedPtr, Transform>> pending;
  auto addInertial = [&](const urdf::LinkConstSharedPtr& start, const Transform& startPose) {
    if (bodies.empty()) return;  // links before the first joint belong to the base
    pending.clear();
    pending.emplace_back(start, startPose);
    while (!pending.empty()) {
      const urdf::LinkConstSharedPtr link = pending.back().first;
      const Transform pose = pending.back().second;
      pending.pop_back();
      if (link->inertial) {
        const Transform in = Transform(pose * toTransform(link->inertial->origin));
        const Eigen::Matrix3d R = in.topLeftCorner<3, 3>();
        Eigen::Matrix3d I;
        const urdf::Inertial& i = *link->inertial;
        I << i.ixx, i.ixy, i.ixz, i.ixy, i.iyy, i.iyz, i.ixz, i.iyz, i.izz;
        bodies.back().add(i.mass, in.topRightCorner<3, 1>(), R * I * R.transpose());
      }
      for (const urdf::JointSharedPtr& c : link->child_joints) {
        if (c->type != urdf::Joint::FIXED) continue;
        if (chainLinks.count(c->child_link_name)) continue;
        pending.emplace_back(robot->getLink(c->child_link_name),
                             Transform(pose * toTransform(c->parent_to_joint_origin_transform)));
      }
    }
  };
  for (const urdf::JointConstSharedPtr& j : chain) {
    if (!finite(j->parent_to_joint_origin_transform))
      throw UrdfError(fileName + ": joint '" + excerpt(j->name) + "' has an origin that is not finite");
    const Transform jointFrame = Transform(linkPose * toTransform(j->parent_to_joint_origin_transform));
    switch (j->type) {
      case urdf::Joint::REVOLUTE:
      case urdf::Joint::CONTINUOUS:
      case urdf::Joint::PRISMATIC: {
        V3 axis(j->axis.x, j->axis.y, j->axis.z);
        if (!axis.allFinite()) throw UrdfError(fileName + ": joint '" + excerpt(j->name) + "' has an axis that is not finite");
        if (axis.norm() < 1e-12) throw UrdfError(fileName + ": joint '" + j->name + "' has a zero axis");
        axis = jointFrame.topLeftCorner<3, 3>() * axis.normalized();
        axes.push_back({V3(jointFrame.topRightCorner<3, 1>()), axis});
        movable.push_back(j);
        bodies.emplace_back();
        break;
      }
      case urdf::Joint::FIXED:
        break;
      default:
        throw UrdfError(fileName + ": joint '" + j->name +
                        "' is floating or planar; a manipulator is a chain of revolute, continuous, prismatic and fixed joints");
    }
    linkPose = jointFrame;
    addInertial(robot->getLink(j->child_link_name), linkPose);
  }
  const int n = static_cast<int>(axes.size());
  if (n == 0) throw UrdfError(fileName + ": no revolute, continuous or prismatic joint between the root and '" + tip->name + "'");
  if (n > kMaxJoints) throw UrdfError(fileName + ": " + std::to_string(n) + " joints; at most " + std::to_string(kMaxJoints));

  // Standard DH frames F_0..F_n in root coordinates (a prismatic joint's line is taken through its
  // joint origin: only its direction matters): z_{i-1} along joint i's axis, x_i along the
  // common normal from axis i to axis i+1, origin of F_i on axis i+1; F_n = F_{n-1}.
  std::vector<Transform> F(static_cast<std::size_t>(n + 1));
  std::vector<V3> origin(static_cast<std::size_t>(n + 1)), xs(static_cast<std::size_t>(n + 1));
  for (int i = 1; i < n; ++i) {  // frame i from axes i-1 and i (0-based lines)
    const Line& a = axes[static_cast<std::size_t>(i - 1)];
    const Line& b = axes[static_cast<std::size_t>(i)];
    const V3 cross = a.direction.cross(b.direction);
    V3 o, x;
    if (cross.norm() > 1e-9) {
      // Closest points of the two lines.
      const V3 w = a.point - b.point;
      const double A = a.direction.dot(a.direction), B = a.direction.dot(b.direction), C = b.direction.dot(b.direction),
                   D = a.direction.dot(w), E = b.direction.dot(w), den = A * C - B * B;
      const double t = (B * E - C * D) / den, s = (A * E - B * D) / den;
      const V3 pa = a.point + t * a.direction, pb = b.point + s * b.direction;
      o = pb;
      x = (pb - pa).norm() > 1e-9 ? V3((pb - pa).normalized()) : V3(cross.normalized());
    } else {
      // Parallel axes: origin where the perpendicular from the previous origin meets axis i.
      const V3 prev = i == 1 ? a.point : origin[static_cast<std::size_t>(i - 1)];
      const V3 foot = b.point + (prev - b.point).dot(b.direction) * b.direction;
      o = foot;
      const V3 between = foot - prev - (foot - prev).dot(a.direction) * a.direction;
      x = between.norm() > 1e-9 ? V3(between.normalized()) : V3::Zero();
    }
    origin[static_cast<std::size_t>(i)] = o;
    xs[static_cast<std::size_t>(i)] = x;
  }
  // Frame 0: on axis 0 with x along frame 1's x if that is perpendicular, else any perpendicular.
  const V3 z0 = axes[0].direction;
  V3 x0 = n > 1 && xs[1].norm() > 0.5 ? xs[1] : anyPerpendicular(z0);
  x0 = (x0 - x0.dot(z0) * z0).normalized();
  origin[0] = axes[0].point;
  F[0] = frame(origin[0], z0, x0);
  for (int i = 1; i < n; ++i) {
    V3 x = xs[static_cast<std::size_t>(i)];
    const V3 z = axes[static_cast<std::size_t>(i)].direction;
    if (x.norm() < 0.5) x = F[static_cast<std::size_t>(i - 1)].block<3, 1>(0, 0);  // coincident axes: keep x
    x = (x - x.dot(z) * z).normalized();
    F[static_cast<std::size_t>(i)] = frame(origin[static_cast<std::size_t>(i)], z, x);
  }
  F[static_cast<std::size_t>(n)] = F[static_cast<std::size_t>(n - 1)];

  std::vector<LinkParameters> links(static_cast<std::size_t>(n));
  for (int i = 1; i <= n; ++i) {
    const Transform& P = F[static_cast<std::size_t>(i - 1)];
    const Transform& Q = F[static_cast<std::size_t>(i)];
    const V3 zp = P.block<3, 1>(0, 2), xp = P.block<3, 1>(0, 0), zq = Q.block<3, 1>(0, 2), xq = Q.block<3, 1>(0, 0);
    const V3 dp = Q.topRightCorner<3, 1>() - P.topRightCorner<3, 1>();
    LinkParameters& l = links[static_cast<std::size_t>(i - 1)];
    l.a = dp.dot(xq);
    l.d = dp.dot(zp);
    l.alpha = std::atan2(zp.cross(zq).dot(xq), zp.dot(zq));
    l.offset = std::atan2(xp.cross(xq).dot(zp), xp.dot(xq));
    const urdf::JointConstSharedPtr& j = movable[static_cast<std::size_t>(i - 1)];
    // A prismatic joint slides along z_{i-1}, which moves the rest of the chain without changing
    // the common normals: d_i = q_i + d (at q = 0 as measured) and theta_i = offset constant.
    if (j->type == urdf::Joint::PRISMATIC) l.type = JointType::Prismatic;
    if (j->type == urdf::Joint::CONTINUOUS || !j->limits) {
      l.positionMin = -2 * std::numbers::pi;
      l.positionMax = 2 * std::numbers::pi;
    } else {
      l.positionMin = j->limits->lower;
      l.positionMax = j->limits->upper;
      if (!(l.positionMin <= l.positionMax)) {
        char range[96];
        std::snprintf(range, sizeof range, "lower %g is above upper %g", l.positionMin, l.positionMax);
        throw UrdfError(fileName + ": joint '" + excerpt(j->name) + "': <limit> " + range);
      }
    }
    if (j->limits && j->limits->effort > 0) l.torqueLimit = j->limits->effort;
    if (j->limits && j->limits->velocity > 0) l.velocityLimit = j->limits->velocity;
    if (j->dynamics) {
      l.viscousFriction = j->dynamics->damping;
      l.coulombFrictionPositive = j->dynamics->friction;
      l.coulombFrictionNegative = -j->dynamics->friction;
    }
    // Inertia of the link (and what is fixed to it) in DH frame i.
    const Body& body = bodies[static_cast<std::size_t>(i - 1)];
    const std::string childName = j->child_link_name;
    if (!body.any) {
      if (options.requireDynamics) {
        throw UrdfError(fileName + ": link '" + childName + "' has no inertial data (needed for dynamics and simulation)");
      }
      continue;
    }
    // A massless link may still have rotational inertia (the Puma's link 1); its centre of mass
    // is then immaterial and taken at the frame origin.
    const V3 c = body.mass > 0 ? V3(body.moment / body.mass) : V3(Q.topRightCorner<3, 1>());
    const Eigen::Matrix3d Ic =
        body.inertiaAtOrigin - body.mass * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
    const Eigen::Matrix3d R = Q.topLeftCorner<3, 3>();
    l.mass = body.mass;
    l.com = Vector<3>(R.transpose() * (c - V3(Q.topRightCorner<3, 1>())));
    l.inertia = Matrix<3, 3>(R.transpose() * Ic * R);
  }
  const Transform tool = Transform(rigidInverse(F[static_cast<std::size_t>(n)]) * linkPose);
  std::unique_ptr<ManipulatorModel> model;
  try {
    model = std::make_unique<ManipulatorModel>(robot->getName(), links, F[0], tool);
  } catch (const std::invalid_argument& e) {  // whatever the model itself refuses, named by file
    throw UrdfError(fileName + ": " + e.what());
  }
  // Self-check: the DH chain must reproduce the URDF's poses at q = 0.
  ManipulatorData data(*model);
  const Transform& T = forwardKinematics(*model, data, JointVector(n));
  if ((T - linkPose).cwiseAbs().maxCoeff() > 1e-9) {
    throw UrdfError(fileName + ": internal error converting the chain to DH frames");
  }
  return model;
}

}  // namespace rp
