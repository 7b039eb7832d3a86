// Loading manipulator models from URDF (rp/model/UrdfModel.hpp).
#include "rp/model/UrdfModel.hpp"

#include <console_bridge/console.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <tinyxml.h>
#include <unistd.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <numbers>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "../core/ShortNumber.hpp"
#include "rp/model/Kinematics.hpp"

namespace rp {

namespace {

using V3 = Eigen::Vector3d;

constexpr std::size_t kMaxUrdfBytes = std::size_t{64} << 20;  // largest URDF file read
constexpr std::size_t kMaxUrdfDepth = 100;                     // deepest element nesting accepted
// Bounds of a physical robot, so that no product of the loader or the dynamics overflows (a finite
// origin of 1e308 m gave NaN torques); the messages quote them.
constexpr double kMaxLength = 1e6;    // largest coordinate of a joint's or inertial's origin [m]
constexpr double kMaxMass = 1e9;      // largest mass of a link's <inertial> [kg]
constexpr double kMaxInertia = 1e12;  // largest magnitude of an inertia entry [kg m^2]

Transform toTransform(const urdf::Pose& p) {
  Transform t = Transform::unit();
  t.topLeftCorner<3, 3>() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z).toRotationMatrix();
  t(0, 3) = p.position.x;
  t(1, 3) = p.position.y;
  t(2, 3) = p.position.z;
  return t;
}

// The inertial parts of one model link (its URDF link and what is fixed to it), in the link's
// model frame.
struct Body {
  struct Part {
    double mass;
    V3 com;
    Eigen::Matrix3d inertia;  // about the part's centre of mass
  };
  std::vector<Part> parts;
  void add(double m, const V3& c, const Eigen::Matrix3d& Ic) { parts.push_back({m, c, Ic}); }
  // The whole: mass, centre of mass and inertia about it (parallel axes about the common centre,
  // so a single part comes out exactly as given). A massless body (which may still have
  // rotational inertia, like the Puma's link 1) has its centre at the frame origin.
  void combine(double& mass, Vector<3>& com, Matrix<3, 3>& inertia) const {
    double m = 0;
    V3 moment = V3::Zero();
    for (const Part& p : parts) {
      m += p.mass;
      moment += p.mass * p.com;
    }
    const V3 c = parts.size() == 1 ? parts[0].com : m > 0 ? V3(moment / m) : V3::Zero();
    Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
    for (const Part& p : parts) {
      const V3 r = p.com - c;
      I += p.inertia;
      if (p.mass != 0) I += p.mass * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
    }
    mass = m;
    com = Vector<3>(c);
    inertia = Matrix<3, 3>(I);
  }
};

// One movable joint of the chain and the link it moves.
struct ChainLink {
  urdf::JointConstSharedPtr joint;
  Transform placement;  // P_i of DHConvention::Placement
  Body body;
};

// The rotation whose z axis is the unit vector `z` (x completed from a coordinate axis): the unit
// matrix for z itself and exact signed permutations for the other coordinate axes, so that
// axis-aligned joints add no rounding at all.
Eigen::Matrix3d axisRotation(const V3& z) {
  const V3 trial = std::abs(z.x()) < 0.9 ? V3::UnitX() : V3::UnitY();
  const V3 x = (trial - trial.dot(z) * z).normalized();
  Eigen::Matrix3d R;
  R.col(0) = x;
  R.col(1) = z.cross(x);
  R.col(2) = z;
  return R;
}

// "%g" of a number (six significant digits, as a URDF file usually gives them).
std::string shortNumber(double x) { return internal::shortNumber(x, 6); }

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

// An optional attribute of three numbers ("x y z"): absent, or three finite numbers. `largest`
// (if not null) receives the largest magnitude of the three (0 if absent).
bool finiteTriple(const TiXmlElement* e, const char* name, double* largest = nullptr) {
  if (largest) *largest = 0;
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
    if (largest) *largest = std::max(*largest, std::abs(v));
    ++count;
    i = end;
  }
  return count == 3;
}

// Checks every link's <inertial> in the XML itself: urdfdom drops an inertial it cannot parse
// (mass="nan", a missing inertia attribute) with a message on stderr and loads a massless link.
// Numbers beyond kMaxLength, kMaxMass or kMaxInertia, and an inertia that is not positive
// semi-definite (a negative principal moment: the mass matrix would lose its positive diagonal),
// are refused as well. The triangle inequality of the principal moments is not enforced: real
// descriptions break it slightly (the published Puma 560 does; see physicalModel()).
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
    double farthest = 0;
    finiteTriple(origin, "xyz", &farthest);
    if (farthest > kMaxLength)
      throw UrdfError(where + "origin xyz " + quoted(origin, "xyz") + " has a coordinate larger than 1e6 m in magnitude");
    const TiXmlElement* mass = inertial->FirstChildElement("mass");
    double m = 0;
    if (!finiteAttribute(mass, "value", m))
      throw UrdfError(where + "mass value is not a finite number (" + quoted(mass, "value") + ")");
    if (m < 0) throw UrdfError(where + "mass " + quoted(mass, "value") + " is negative");
    if (m > kMaxMass) throw UrdfError(where + "mass " + quoted(mass, "value") + " is larger than 1e9 kg");
    const TiXmlElement* inertia = inertial->FirstChildElement("inertia");
    double v[6] = {};  // ixx, ixy, ixz, iyy, iyz, izz
    int k = 0;
    for (const char* name : {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"}) {
      if (!finiteAttribute(inertia, name, v[k]))
        throw UrdfError(where + "inertia " + name + " is not a finite number (" + quoted(inertia, name) + ")");
      if (std::abs(v[k]) > kMaxInertia)
        throw UrdfError(where + "inertia " + name + " " + quoted(inertia, name) + " is larger than 1e12 kg m^2 in magnitude");
      ++k;
    }
    Eigen::Matrix3d I;
    I << v[0], v[1], v[2], v[1], v[3], v[4], v[2], v[4], v[5];
    // Relative to the largest principal moment: files written with 5 significant digits put a
    // thin rod's smallest moment at -1e-5 of it (an absolute bound refused them).
    const Eigen::Vector3d moments = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(I, Eigen::EigenvaluesOnly).eigenvalues();
    const double smallest = moments(0);
    if (smallest < -1e-4 * moments.cwiseAbs().maxCoeff() - 1e-12)
      throw UrdfError(where + "inertia is not positive semi-definite (smallest eigenvalue " + shortNumber(smallest) +
                      " kg m^2)");
  }
}

// Checks the numbers of every joint in the XML itself: urdfdom refuses a joint whose <limit> holds
// `nan` with "not a valid URDF document", naming neither the joint nor the value. An origin
// farther than kMaxLength is refused too.
void checkJointNumbers(const TiXmlElement* robot, const std::string& fileName) {
  for (const TiXmlElement* joint = robot->FirstChildElement("joint"); joint; joint = joint->NextSiblingElement("joint")) {
    const char* nameAttribute = joint->Attribute("name");
    const std::string where = fileName + ": joint '" + excerpt(nameAttribute ? nameAttribute : "") + "': <";
    auto quoted = [](const TiXmlElement* e, const char* name) {
      std::string q(1, '\'');  // appended piece by piece: GCC 12 warns (-Wrestrict) about "'" + s
      q += excerpt(e->Attribute(name));
      q += '\'';
      return q;
    };
    for (const char* element : {"origin", "axis"}) {
      const TiXmlElement* e = joint->FirstChildElement(element);
      for (const char* name : {"xyz", "rpy"})
        if (e && !finiteTriple(e, name))
          throw UrdfError(where + element + "> " + name + " " + quoted(e, name) + " is not three finite numbers");
    }
    const TiXmlElement* origin = joint->FirstChildElement("origin");
    double farthest = 0;
    finiteTriple(origin, "xyz", &farthest);
    if (farthest > kMaxLength)
      throw UrdfError(where + "origin> xyz " + quoted(origin, "xyz") + " has a coordinate larger than 1e6 m in magnitude");
    const std::pair<const char*, std::vector<const char*>> numbers[] = {
        {"limit", {"lower", "upper", "effort", "velocity"}}, {"dynamics", {"damping", "friction"}}, {"mimic", {"multiplier", "offset"}}};
    for (const auto& [element, names] : numbers) {
      const TiXmlElement* e = joint->FirstChildElement(element);
      if (!e) continue;
      for (const char* name : names) {
        double v = 0;
        if (e->Attribute(name) && !finiteAttribute(e, name, v))
          throw UrdfError(where + element + "> " + name + " is not a finite number (" + quoted(e, name) + ")");
      }
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
  checkJointNumbers(robot, fileName);
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

// The URDF's own forward kinematics of the chain: the product of each joint's origin and its
// motion about (or along) its axis.
Transform walkChain(const std::vector<urdf::JointConstSharedPtr>& chain, const JointVector& q) {
  Transform T = Transform::unit();
  int k = 0;
  for (const urdf::JointConstSharedPtr& j : chain) {
    T = Transform(T * toTransform(j->parent_to_joint_origin_transform));
    if (j->type == urdf::Joint::FIXED) continue;
    const V3 axis = V3(j->axis.x, j->axis.y, j->axis.z).normalized();
    Transform M = Transform::unit();
    if (j->type == urdf::Joint::PRISMATIC) M.topRightCorner<3, 1>() = q(k) * axis;
    else M.topLeftCorner<3, 3>() = Eigen::AngleAxisd(q(k), axis).toRotationMatrix();
    T = Transform(T * M);
    ++k;
  }
  return T;
}

// Self-check: the model's forward kinematics must reproduce the description's at the zero
// configuration and at a few spread over the joint ranges (a deterministic sequence, the same for
// every load).
void selfCheck(const ManipulatorModel& model, const std::vector<urdf::JointConstSharedPtr>& chain,
               const std::string& fileName) {
  const int n = model.getNumberOfJoints();
  ManipulatorData data(model);
  JointVector q(n), chainQ;
  for (int trial = 0; trial < 5; ++trial) {
    for (int i = 0; i < n; ++i) {
      const double lo = model.getPositionMin()(i), hi = model.getPositionMax()(i);
      const double fraction = trial == 0 ? -1 : std::fmod(0.6180339887498949 * (i + 1) * (trial + 2) + 0.1 * trial, 1.0);
      q(i) = trial == 0 ? std::clamp(0.0, lo, hi) : lo + fraction * (hi - lo);
    }
    model.toChain(q, chainQ);  // mimic joints at their master's value times the multiplier plus the offset
    const Transform expected = walkChain(chain, chainQ);
    const Transform& T = forwardKinematics(model, data, q);
    const double scale = 1 + expected.topRightCorner<3, 1>().cwiseAbs().maxCoeff();
    if (!T.allFinite() || !((T - expected).cwiseAbs().maxCoeff() <= 1e-9 * scale)) {
      std::string at;
      for (int i = 0; i < n; ++i) {
        if (i > 0) at += ',';
        at += std::to_string(q(i));
      }
      throw UrdfError(fileName + ": internal error: the model's forward kinematics differs from the description's at q = (" +
                      at + ")");
    }
  }
}

bool isMovable(const urdf::Joint& j) {
  return j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS || j.type == urdf::Joint::PRISMATIC;
}

// Whether a name suggests a gripper's joint or link.
bool looksLikeGripper(std::string name) {
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const char* word : {"grip", "finger", "jaw", "claw"})
    if (name.find(word) != std::string::npos) return true;
  return false;
}

bool isGripperJoint(const urdf::Joint& j) { return looksLikeGripper(j.name) || looksLikeGripper(j.child_link_name); }

// UrdfOptions::offChainPositions checked against the description and in radians and metres: each
// name a revolute, continuous or prismatic joint off the chain (`chainLinks`: the child links of
// the chain's joints), each value finite and within the joint's limits. Whether a joint moves a
// link that is lumped into the arm is checked after the walk (loadUrdf()).
std::map<std::string, double> offChainPositions(const urdf::ModelInterface& robot, const UrdfOptions& options,
                                                const std::unordered_set<std::string>& chainLinks,
                                                const std::string& fileName) {
  std::string movingOff;  // the moving joints off the chain, for messages
  for (const auto& [name, joint] : robot.joints_)
    if (joint && isMovable(*joint) && !chainLinks.count(joint->child_link_name))
      movingOff += (movingOff.empty() ? "" : ", ") + excerpt(name);
  const std::string candidates = " (moving joints off the chain: " + (movingOff.empty() ? std::string("none") : movingOff) + ")";
  auto fail = [&](const std::string& problem) { return UrdfOptionError(fileName, "offChainPositions", problem); };
  std::map<std::string, double> si;
  for (const auto& [name, given] : options.offChainPositions) {
    const std::string joint = "joint '" + excerpt(name) + "'";
    const urdf::JointConstSharedPtr j = robot.getJoint(name);
    if (!j) throw fail("there is no " + joint + candidates);
    if (!std::isfinite(given)) throw fail(joint + ": the value is not finite");
    if (!isMovable(*j)) throw fail(joint + " is fixed, floating or planar: it has no position" + candidates);
    if (chainLinks.count(j->child_link_name)) throw fail(joint + " is a joint of the arm, not off the chain" + candidates);
    const bool prismatic = j->type == urdf::Joint::PRISMATIC;
    const char* unit = options.offChainInDegreesAndMillimetres ? (prismatic ? " mm" : " deg") : (prismatic ? " m" : " rad");
    const double scale = !options.offChainInDegreesAndMillimetres ? 1.0 : prismatic ? 1e-3 : std::numbers::pi / 180;
    const double value = given * scale;
    if (j->limits && j->type != urdf::Joint::CONTINUOUS && (value < j->limits->lower || value > j->limits->upper))
      throw fail(joint + ": " + shortNumber(given) + unit + " is outside its limits " + shortNumber(j->limits->lower / scale) +
                 " .. " + shortNumber(j->limits->upper / scale) + unit);
    si[name] = value;
  }
  return si;
}

// The default tip: from the root, follow the one child joint whose subtree moves (a branch that
// carries only fixed frames, such as tool0 or a camera, is no branch) to the last moving link.
// Where everything that moves further on is a gripper (joints or links named grip..., finger,
// jaw, claw), the arm ends there and the gripper is lumped (see loadUrdf()). Two or more other
// moving subtrees are a real choice: refused, listing the leaf links below as candidate tips.
urdf::LinkConstSharedPtr defaultTip(const urdf::ModelInterface& robot, const urdf::LinkConstSharedPtr& root,
                                    const std::string& fileName) {
  // Links with a movable joint somewhere below them, and with one that is not a gripper's, marked
  // upwards from each movable joint (each link is marked once).
  std::unordered_set<const urdf::Link*> movesBelow, armBelow;
  auto markUp = [&](const urdf::Joint& joint, std::unordered_set<const urdf::Link*>& marks) {
    for (urdf::LinkConstSharedPtr link = robot.getLink(joint.parent_link_name); link && marks.insert(link.get()).second;
         link = link->parent_joint ? robot.getLink(link->parent_joint->parent_link_name) : nullptr) {
    }
  };
  // (Floating and planar joints count as moving, so that a chain through one is refused by name.)
  auto moving = [](const urdf::Joint& j) { return j.type != urdf::Joint::FIXED; };
  for (const auto& [name, joint] : robot.joints_) {
    if (!joint || !moving(*joint)) continue;
    markUp(*joint, movesBelow);
    if (!isGripperJoint(*joint)) markUp(*joint, armBelow);
  }
  auto below = [&](const urdf::JointConstSharedPtr& j, const std::unordered_set<const urdf::Link*>& marks) {
    const urdf::LinkConstSharedPtr child = robot.getLink(j->child_link_name);
    return child && marks.count(child.get()) > 0;
  };
  urdf::LinkConstSharedPtr link = root, lastMoving;
  for (;;) {
    std::vector<urdf::JointConstSharedPtr> branches;
    bool arm = false;  // something that is not a gripper moves further on
    for (const urdf::JointSharedPtr& c : link->child_joints) {
      if (!c || !(moving(*c) || below(c, movesBelow))) continue;
      branches.push_back(c);
      arm = arm || (moving(*c) && !isGripperJoint(*c)) || below(c, armBelow);
    }
    if (branches.empty() || !arm) break;
    if (branches.size() > 1) {
      std::vector<std::string> leaves;
      std::vector<urdf::LinkConstSharedPtr> todo{link};
      while (!todo.empty()) {
        const urdf::LinkConstSharedPtr l = todo.back();
        todo.pop_back();
        if (l->child_joints.empty()) leaves.push_back(l->name);
        for (const urdf::JointSharedPtr& c : l->child_joints)
          if (c) todo.push_back(robot.getLink(c->child_link_name));
      }
      std::sort(leaves.begin(), leaves.end());
      std::string list;
      for (std::size_t i = 0; i < leaves.size() && i < 12; ++i) {
        if (i > 0) list += ", ";
        list += '\'';  // piece by piece: GCC 12 warns (-Wrestrict) about "'" + s
        list += excerpt(leaves[i]);
        list += '\'';
      }
      if (leaves.size() > 12) list += ", ...";
      throw UrdfError(fileName + ": the robot branches at link '" + excerpt(link->name) + "' into " +
                      std::to_string(branches.size()) + " moving chains; name the tip link, one of " + list);
    }
    const urdf::JointConstSharedPtr j = branches.front();
    link = robot.getLink(j->child_link_name);
    if (moving(*j)) lastMoving = link;
  }
  return lastMoving ? lastMoving : link;
}

// Every mimic joint names an existing joint other than itself, with a finite multiplier and
// offset, and mimics do not go round in a circle.
void checkMimics(const urdf::ModelInterface& robot, const std::string& fileName) {
  for (const auto& [name, joint] : robot.joints_) {
    if (!joint || !joint->mimic) continue;
    const std::string where = fileName + ": joint '" + excerpt(name) + "' mimics ";
    const urdf::JointMimic& m = *joint->mimic;
    if (!robot.getJoint(m.joint_name)) throw UrdfError(where + "joint '" + excerpt(m.joint_name) + "', which does not exist");
    if (!std::isfinite(m.multiplier) || !std::isfinite(m.offset))
      throw UrdfError(where + "'" + excerpt(m.joint_name) + "' with a multiplier or offset that is not finite");
    std::unordered_set<std::string> seen{name};
    for (urdf::JointConstSharedPtr j = robot.getJoint(m.joint_name); j && j->mimic; j = robot.getJoint(j->mimic->joint_name))
      if (!seen.insert(j->name).second) throw UrdfError(where + "'" + excerpt(m.joint_name) + "': the mimic joints go round in a circle");
  }
}

// urdfdom's parser, with the errors it reports (through console_bridge, on stderr by default)
// collected for the UrdfError instead: they name the joint or link it refused. Its warnings still
// go where console_bridge's handler sent them. The handler is global: one parse at a time, and the
// collector is never destroyed (console_bridge keeps a pointer to it as its "previous" handler).
urdf::ModelInterfaceSharedPtr parseCollectingErrors(const std::string& text, std::vector<std::string>& errors) {
  struct Collector : console_bridge::OutputHandler {
    console_bridge::OutputHandler* previous = nullptr;
    std::vector<std::string>* errors = nullptr;  // null: forward everything
    void log(const std::string& message, console_bridge::LogLevel level, const char* file, int line) override {
      if (errors && level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) errors->push_back(message);
      else if (previous) previous->log(message, level, file, line);
    }
  };
  static std::mutex parsing;
  static Collector* const collector = new Collector;
  const std::lock_guard<std::mutex> lock(parsing);
  if (console_bridge::OutputHandler* current = console_bridge::getOutputHandler(); current != collector)
    collector->previous = current;
  collector->errors = &errors;
  console_bridge::useOutputHandler(collector);
  struct Restore {
    ~Restore() {
      collector->errors = nullptr;
      console_bridge::useOutputHandler(collector->previous);
    }
  } restore;
  return urdf::parseURDF(text);
}

// Why urdfdom refused the document: where the XML is malformed, "LINE:COLUMN: ... malformed XML
// (what)"; otherwise the errors urdfdom reported (naming the joint or link).
std::string invalidDocument(const std::string& text, const std::string& fileName, const std::vector<std::string>& errors) {
  constexpr const char* kInvalid = "not a valid URDF document";
  TiXmlDocument doc;
  doc.Parse(text.c_str());
  if (doc.Error()) {
    std::string what = doc.ErrorDesc();
    while (!what.empty() && (what.back() == '.' || std::isspace(static_cast<unsigned char>(what.back())))) what.pop_back();
    return fileName + ":" + std::to_string(doc.ErrorRow()) + ":" + std::to_string(doc.ErrorCol()) + ": " + kInvalid +
           ": malformed XML (" + what + ")";
  }
  std::string reasons;
  for (const std::string& e : errors) {
    if (e == "joint xml is not initialized correctly" || e == "link xml is not initialized correctly")
      continue;  // urdfdom's follow-up to the error before it
    reasons += reasons.empty() ? "" : "; ";
    reasons += e;
  }
  return fileName + ": " + kInvalid + (reasons.empty() ? std::string(" (malformed XML or URDF structure)") : ": " + reasons);
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
  return loadUrdfString(readUrdfFile(fileName), options, fileName);
}

std::unique_ptr<ManipulatorModel> loadUrdfString(const std::string& text, const UrdfOptions& options,
                                                 const std::string& fileName) {
  if (!(std::isfinite(options.velocityLimitScale) && options.velocityLimitScale > 0)) {
    std::ostringstream value;
    value << options.velocityLimitScale;
    throw UrdfOptionError(fileName, "velocityLimitScale", "must be a positive number, not " + value.str());
  }
  checkNesting(text, fileName);
  checkDocument(text, fileName);
  std::vector<std::string> urdfdomErrors;
  const urdf::ModelInterfaceSharedPtr robot = parseCollectingErrors(text, urdfdomErrors);
  if (!robot) throw UrdfError(invalidDocument(text, fileName, urdfdomErrors));
  const UnlinkOnExit unlink{*robot};
  const urdf::LinkConstSharedPtr root = robot->getRoot();
  if (!root) throw UrdfError(fileName + ": the robot has no root link");
  checkTree(*robot, *root, fileName);
  checkMimics(*robot, fileName);

  // The chain of joints from the root to the tip.
  urdf::LinkConstSharedPtr tip;
  if (!options.tip.empty()) {
    tip = robot->getLink(options.tip);
    if (!tip) throw UrdfError(fileName + ": there is no link '" + options.tip + "'");
  } else {
    tip = defaultTip(*robot, root, fileName);
  }
  std::vector<urdf::JointConstSharedPtr> chain;
  for (urdf::LinkConstSharedPtr link = tip; link->parent_joint; link = robot->getLink(link->parent_joint->parent_link_name)) {
    chain.push_back(link->parent_joint);
  }
  std::reverse(chain.begin(), chain.end());

  // The chain as the file says it (the Placement form): link frame i is the child link of movable
  // joint i turned by axisRotation() so that its z axis is the joint's axis, and P_i places that
  // frame (at q_i = 0) in link frame i-1. `C` is the pose, at q = 0, of the URDF link being
  // walked in the current model frame (the root frame before the first joint).
  std::vector<ChainLink> links;
  Transform C = Transform::unit();
  std::unordered_set<std::string> chainLinks;
  for (const urdf::JointConstSharedPtr& j : chain) chainLinks.insert(j->child_link_name);
  // The value at which a moving joint off the chain is lumped: the user's, its master's for a
  // mimic joint (multiplier and offset), or zero within its limits.
  const std::map<std::string, double> given = offChainPositions(*robot, options, chainLinks, fileName);
  std::set<std::string> used;  // the joints of `given` a lumped link's position was taken from
  auto offChainValue = [&](const urdf::Joint& joint) {
    const urdf::Joint* j = &joint;
    double multiplier = 1, offset = 0;
    for (std::size_t depth = 0; depth <= robot->joints_.size(); ++depth) {
      if (const auto it = given.find(j->name); it != given.end()) {
        used.insert(j->name);
        return multiplier * it->second + offset;
      }
      if (!j->mimic) break;
      offset += multiplier * j->mimic->offset;
      multiplier *= j->mimic->multiplier;
      j = robot->getJoint(j->mimic->joint_name).get();
    }
    double v = 0;
    if (j->limits && j->type != urdf::Joint::CONTINUOUS) {
      // (std::clamp with lower above upper is undefined behaviour, not just a wrong value.)
      if (!(j->limits->lower <= j->limits->upper)) {
        char range[96];
        std::snprintf(range, sizeof range, "lower %g is above upper %g", j->limits->lower, j->limits->upper);
        throw UrdfError(fileName + ": joint '" + excerpt(j->name) + "': <limit> " + range);
      }
      v = std::clamp(0.0, j->limits->lower, j->limits->upper);
    }
    return multiplier * v + offset;
  };
  // A link's inertia and that of everything hanging on it off the chain: fixed (a camera) or
  // moving (fingers, a jaw: at offChainValue(), reported in a note), walked with an explicit
  // stack: a chain of many fixed links must not recurse once per link.
  struct Pending {
    urdf::LinkConstSharedPtr link;
    Transform pose;
    bool moved;  // below a moving joint off the chain
  };
  std::vector<Pending> pending;
  auto addInertial = [&](const urdf::LinkConstSharedPtr& start, const Transform& startPose) {
    if (links.empty()) return;  // links before the first joint belong to the base
    std::string movedLinks, movingJoints;
    pending.clear();
    pending.push_back({start, startPose, false});
    while (!pending.empty()) {
      const Pending p = pending.back();
      pending.pop_back();
      if (p.link->inertial) {
        const Transform in = Transform(p.pose * toTransform(p.link->inertial->origin));
        const Eigen::Matrix3d R = in.topLeftCorner<3, 3>();
        Eigen::Matrix3d I;
        const urdf::Inertial& i = *p.link->inertial;
        I << i.ixx, i.ixy, i.ixz, i.ixy, i.iyy, i.iyz, i.ixz, i.iyz, i.izz;
        links.back().body.add(i.mass, in.topRightCorner<3, 1>(), R * I * R.transpose());
      }
      for (const urdf::JointSharedPtr& c : p.link->child_joints) {
        if (chainLinks.count(c->child_link_name)) continue;
        if (c->type != urdf::Joint::FIXED && !isMovable(*c)) continue;  // a floating or planar body is not carried
        if (!finite(c->parent_to_joint_origin_transform))
          throw UrdfError(fileName + ": joint '" + excerpt(c->name) + "' has an origin that is not finite");
        Transform child = Transform(p.pose * toTransform(c->parent_to_joint_origin_transform));
        if (isMovable(*c)) {
          const V3 axis = V3(c->axis.x, c->axis.y, c->axis.z);
          if (!axis.allFinite() || axis.norm() < 1e-12)
            throw UrdfError(fileName + ": joint '" + excerpt(c->name) + "' has an axis that is zero or not finite");
          const double v = offChainValue(*c);
          Transform motion = Transform::unit();
          if (c->type == urdf::Joint::PRISMATIC) motion.topRightCorner<3, 1>() = v * axis.normalized();
          else motion.topLeftCorner<3, 3>() = Eigen::AngleAxisd(v, axis.normalized()).toRotationMatrix();
          child = Transform(child * motion);
          char value[64];
          std::snprintf(value, sizeof value, " = %g %s", v, c->type == urdf::Joint::PRISMATIC ? "m" : "rad");
          if (!movingJoints.empty()) movingJoints += ", ";
          movingJoints += excerpt(c->name);
          movingJoints += value;
        }
        const bool moved = p.moved || isMovable(*c);
        if (moved) {
          if (!movedLinks.empty()) movedLinks += ", ";
          movedLinks += '\'';  // piece by piece: GCC 12 warns (-Wrestrict) about "'" + s
          movedLinks += excerpt(c->child_link_name);
          movedLinks += '\'';
        }
        pending.push_back({robot->getLink(c->child_link_name), child, moved});
      }
    }
    if (!movedLinks.empty() && options.notes) {
      options.notes->push_back(fileName + ": links " + movedLinks + " move off the chain: their mass is lumped into '" +
                               excerpt(links.back().joint->child_link_name) + "' at " + movingJoints +
                               " (other values: UrdfOptions::offChainPositions, rp.cfg offChainPositions, rp-model --offchain)");
    }
  };
  for (const urdf::JointConstSharedPtr& j : chain) {
    const std::string joint = fileName + ": joint '" + excerpt(j->name) + "'";
    if (!finite(j->parent_to_joint_origin_transform)) throw UrdfError(joint + " has an origin that is not finite");
    const Transform origin = toTransform(j->parent_to_joint_origin_transform);
    switch (j->type) {
      case urdf::Joint::REVOLUTE:
      case urdf::Joint::CONTINUOUS:
      case urdf::Joint::PRISMATIC: {
        V3 axis(j->axis.x, j->axis.y, j->axis.z);
        if (!axis.allFinite()) throw UrdfError(joint + " has an axis that is not finite");
        if (axis.norm() < 1e-12) throw UrdfError(joint + " has a zero axis");
        const Eigen::Matrix3d Ra = axisRotation(axis.normalized());
        ChainLink link;
        link.joint = j;
        link.placement = Transform(C * origin);
        link.placement.topLeftCorner<3, 3>() = Eigen::Matrix3d(link.placement.topLeftCorner<3, 3>() * Ra);
        links.push_back(std::move(link));
        C = Transform::unit();
        C.topLeftCorner<3, 3>() = Ra.transpose();
        break;
      }
      case urdf::Joint::FIXED:
        C = Transform(C * origin);
        break;
      default:
        throw UrdfError(joint + " is floating or planar; a manipulator is a chain of revolute, continuous, prismatic and fixed joints");
    }
    addInertial(robot->getLink(j->child_link_name), C);
  }
  for (const auto& entry : given)
    if (!used.count(entry.first))
      throw UrdfOptionError(fileName, "offChainPositions",
                            "joint '" + excerpt(entry.first) +
                                "' moves no link that is lumped into the arm (it hangs on the base, or below a floating or planar joint)");
  const int n = static_cast<int>(links.size());
  if (n == 0) throw UrdfError(fileName + ": no revolute, continuous or prismatic joint between the root and '" + tip->name + "'");
  if (n > kMaxJoints) throw UrdfError(fileName + ": " + std::to_string(n) + " joints; at most " + std::to_string(kMaxJoints));

  std::vector<LinkParameters> parameters(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const ChainLink& link = links[static_cast<std::size_t>(i)];
    const urdf::JointConstSharedPtr& j = link.joint;
    const std::string joint = fileName + ": joint '" + excerpt(j->name) + "'";
    LinkParameters& l = parameters[static_cast<std::size_t>(i)];
    l.placement = link.placement;
    l.jointName = j->name;
    l.linkName = j->child_link_name;
    if (j->type == urdf::Joint::PRISMATIC) l.type = JointType::Prismatic;
    if (j->limits) {
      for (const auto& [what, value] : {std::pair<const char*, double>{"lower", j->limits->lower}, {"upper", j->limits->upper},
                                        {"effort", j->limits->effort}, {"velocity", j->limits->velocity}})
        if (!std::isfinite(value)) throw UrdfError(joint + ": <limit> " + what + " is not a finite number");
      // A negative speed or torque bound is no bound at all. Zero is "not given" (urdfdom refuses
      // a <limit> without effort or velocity; tools write 0 as a placeholder): the
      // ManipulatorModel default stays (3 rad/s or m/s, 100 N m or N; not scaled below).
      for (const auto& [what, value] : {std::pair<const char*, double>{"effort", j->limits->effort}, {"velocity", j->limits->velocity}})
        if (value < 0) throw UrdfError(joint + ": <limit> " + what + " " + shortNumber(value) + " is negative");
    }
    if (j->dynamics && (!std::isfinite(j->dynamics->damping) || !std::isfinite(j->dynamics->friction)))
      throw UrdfError(joint + ": <dynamics> damping or friction is not a finite number");
    if (j->type == urdf::Joint::CONTINUOUS || !j->limits) {
      l.positionMin = -2 * std::numbers::pi;
      l.positionMax = 2 * std::numbers::pi;
    } else {
      l.positionMin = j->limits->lower;
      l.positionMax = j->limits->upper;
      if (!(l.positionMin <= l.positionMax)) {
        char range[96];
        std::snprintf(range, sizeof range, "lower %g is above upper %g", l.positionMin, l.positionMax);
        throw UrdfError(joint + ": <limit> " + range);
      }
      // A limit a robot cannot have: some tools write +-1.8e308 for "none", which broke the
      // load's own check ("internal error: ... differs") and every range computed from it.
      for (const auto& [what, value] : {std::pair<const char*, double>{"lower", l.positionMin}, {"upper", l.positionMax}})
        if (std::abs(value) > 1e6)
          throw UrdfError(joint + ": <limit> " + what + " " + shortNumber(value) +
                          " is beyond 1e6 in magnitude (a joint without limits is type=\"continuous\")");
    }
    if (j->limits && j->limits->effort > 0) l.torqueLimit = j->limits->effort;
    if (j->limits && j->limits->velocity > 0) l.velocityLimit = j->limits->velocity * options.velocityLimitScale;
    if (j->dynamics) {
      l.viscousFriction = j->dynamics->damping;
      l.coulombFrictionPositive = j->dynamics->friction;
      l.coulombFrictionNegative = -j->dynamics->friction;
    }
    if (link.body.parts.empty()) {
      if (options.requireDynamics) {
        throw UrdfError(fileName + ": link '" + j->child_link_name + "' has no inertial data (needed for dynamics and simulation)");
      }
      continue;
    }
    link.body.combine(l.mass, l.com, l.inertia);
  }
  // Mimic joints on the chain follow an independent joint of the chain (through other mimic
  // joints: multipliers and offsets composed); they are no joints of the model.
  std::vector<JointCoupling> coupling(static_cast<std::size_t>(n));
  std::map<std::string, int> independent;  // joint name -> the model's joint
  for (int k = 0; k < n; ++k) {
    const urdf::Joint& j = *links[static_cast<std::size_t>(k)].joint;
    if (j.mimic) continue;
    coupling[static_cast<std::size_t>(k)].joint = static_cast<int>(independent.size());
    independent[j.name] = static_cast<int>(independent.size());
  }
  for (int k = 0; k < n; ++k) {
    const urdf::Joint* j = links[static_cast<std::size_t>(k)].joint.get();
    if (!j->mimic) continue;
    JointCoupling& c = coupling[static_cast<std::size_t>(k)];
    c.mimic = true;
    c.multiplier = 1;
    c.offset = 0;
    const std::string name = j->name;
    while (j->mimic) {  // checkMimics() ruled out circles
      c.offset += c.multiplier * j->mimic->offset;
      c.multiplier *= j->mimic->multiplier;
      j = robot->getJoint(j->mimic->joint_name).get();
    }
    const auto master = independent.find(j->name);
    if (master == independent.end())
      throw UrdfError(fileName + ": joint '" + excerpt(name) + "' mimics joint '" + excerpt(j->name) +
                      "', which is not a joint of the chain; a mimic joint on the chain follows a joint of the chain");
    c.joint = master->second;
    if (!std::isfinite(c.multiplier) || !std::isfinite(c.offset))
      throw UrdfError(fileName + ": joint '" + excerpt(name) + "': <mimic> multiplier or offset is not finite when composed");
  }
  std::unique_ptr<ManipulatorModel> model;
  try {
    if (independent.size() == static_cast<std::size_t>(n)) {
      model = std::make_unique<ManipulatorModel>(robot->getName(), parameters, Transform::unit(), C,
                                                 ManipulatorModel::standardGravity(), DHConvention::Placement);
    } else {
      model = std::make_unique<ManipulatorModel>(
          std::make_shared<const ManipulatorModel>(robot->getName(), parameters, Transform::unit(), C,
                                                   ManipulatorModel::standardGravity(), DHConvention::Placement),
          std::move(coupling));
    }
  } catch (const std::invalid_argument& e) {  // whatever the model itself refuses, named by file
    throw UrdfError(fileName + ": " + e.what());
  }
  selfCheck(*model, chain, fileName);
  return model;
}

}  // namespace rp
