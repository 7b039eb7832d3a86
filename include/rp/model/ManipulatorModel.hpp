#pragma once
/// @file
/// The constant description of a serial manipulator: kinematics (Denavit-Hartenberg or general
/// placements), dynamics, drive train and limits (paper section 3.3, Figure 7).

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "rp/math/Matrix.hpp"
#include "rp/math/Transform.hpp"

namespace rp {

/// Largest number of joints a manipulator model may have.
inline constexpr int kMaxJoints = 16;
/// A vector with one value per joint (size set at run time, storage inside: never allocates).
using JointVector = BoundedVector<kMaxJoints>;
/// A joint-space matrix such as the mass matrix (never allocates).
using JointMatrix = BoundedMatrix<kMaxJoints, kMaxJoints>;
/// A geometric Jacobian: 6 rows (vx, vy, vz, wx, wy, wz), one column per joint (never allocates).
using Jacobian = Matrix<6, Dynamic, double, 6, kMaxJoints>;

/// How the link parameters describe the kinematics: one of the Denavit-Hartenberg conventions, or
/// a general fixed placement per link (the form of a URDF chain).
enum class DHConvention {
  /// Standard (distal) DH: \f$A_i = R_z(\theta_i) T_z(d_i) T_x(a_i) R_x(\alpha_i)\f$; link frame
  /// \f$i\f$ sits at the distal end of link \f$i\f$ and joint \f$i\f$ turns about \f$z_{i-1}\f$.
  Standard,
  /// Modified (proximal, Craig 1989) DH: \f$A_i = R_x(\alpha_{i-1}) T_x(a_{i-1}) R_z(\theta_i) T_z(d_i)\f$;
  /// link frame \f$i\f$ sits at the proximal end of link \f$i\f$, on joint \f$i\f$'s axis, and joint
  /// \f$i\f$ moves about or along \f$z_i\f$. LinkParameters `a` and `alpha` of link \f$i\f$ hold
  /// \f$a_{i-1}\f$ and \f$\alpha_{i-1}\f$ (the Robotics Toolbox's `RevoluteMDH` convention).
  Modified,
  /// No DH parameters: \f$A_i = P_i\,J(q_i)\f$ with \f$P_i\f$ the link's `placement` (any
  /// rigid transform: the pose of joint \f$i\f$'s frame in link frame \f$i-1\f$) and
  /// \f$J(q_i) = R_z(q_i)\f$ or \f$T_z(q_i)\f$: joint \f$i\f$ turns about or slides along the
  /// z axis of that frame, and link frame \f$i\f$ is the frame after the motion (as in KDL's
  /// segments and Pinocchio's joint placements). Exact for any chain, whatever its axes: loadUrdf()
  /// builds this form. `a`, `alpha`, `d` and `offset` are then zero.
  Placement,
};

/// The kind of a joint.
enum class JointType {
  Revolute,   ///< turns about its z axis: \f$\theta_i = q_i + \mathrm{offset}_i\f$, joint value in [rad]
  Prismatic,  ///< slides along its z axis: \f$d_i = q_i + d_i^0\f$, joint value in [m]
};

/// Constant parameters of one link and its joint (all SI units, radians).
///
/// The joint variable enters the DH parameters as \f$\theta_i = \mathrm{offset} + q_i\f$ for a
/// revolute joint and \f$d_i = d + q_i\f$ for a prismatic one (whose \f$\theta_i\f$ is then the
/// constant `offset`). For a prismatic joint, position limits are in [m], speeds in [m/s],
/// torques are forces [N] and inertias masses [kg].
///
/// Friction and motor inertia follow the Robotics Toolbox's convention: they are given on the
/// motor side and reflected to the joint through the gear ratio \f$G\f$: armature inertia
/// \f$G^2 J_m\f$, viscous friction \f$B G^2 \dot q\f$ and Coulomb friction \f$|G| T_c\f$.
struct LinkParameters {
  double a = 0;       ///< DH link length [m]
  double alpha = 0;   ///< DH link twist [rad]
  double d = 0;       ///< DH link offset [m]; for a prismatic joint the offset of \f$d_i = q_i + d\f$
  double offset = 0;  ///< joint angle offset: \f$\theta_i = q_i + \mathrm{offset}\f$ (prismatic: \f$\theta_i\f$) [rad]

  double mass = 0;                          ///< link mass [kg]
  Vector<3> com;                            ///< centre of mass in link frame \f$i\f$ [m]
  Matrix<3, 3> inertia;                     ///< inertia tensor about the centre of mass, in frame \f$i\f$ [kg m^2]
  double motorInertia = 0;                  ///< motor (armature) inertia \f$J_m\f$, motor side [kg m^2]
  double gearRatio = 1;                     ///< gear ratio \f$G\f$ (motor turns per joint turn; sign allowed)
  double viscousFriction = 0;               ///< viscous friction \f$B\f$, motor side [N m s/rad]
  double coulombFrictionPositive = 0;       ///< Coulomb friction for \f$\dot q > 0\f$, motor side [N m] (>= 0)
  double coulombFrictionNegative = 0;       ///< Coulomb friction for \f$\dot q < 0\f$, motor side [N m] (<= 0)

  double positionMin = -3.14159265358979;   ///< lower joint limit [rad]
  double positionMax = 3.14159265358979;    ///< upper joint limit [rad]
  double velocityLimit = 3.0;               ///< largest joint speed [rad/s]
  double accelerationLimit = 10.0;          ///< largest joint acceleration for trajectories [rad/s^2]
  double jerkLimit = 100.0;                 ///< largest joint jerk for trajectories [rad/s^3]
  double torqueLimit = 100.0;               ///< largest joint torque [N m]
  JointType type = JointType::Revolute;     ///< revolute or prismatic joint

  /// DHConvention::Placement only (the unit transform otherwise): the pose of joint i's frame in
  /// link frame i-1 at \f$q_i = 0\f$ (link frame 0 is the base frame) [m].
  Transform placement = Transform::unit();
  std::string jointName;  ///< name of joint i (unique in the model); empty: `joint1`, `joint2`, ...
  std::string linkName;   ///< name of link i, the body joint i moves (unique); empty: `link1`, `link2`, ...
};

/// How joint k of a chain with mimic joints moves (ManipulatorModel::getCoupling()): an
/// independent joint of the model, or a mimic joint that follows one,
/// \f$q^{\mathrm{chain}}_k = \mathrm{multiplier}\,q_{\mathrm{joint}} + \mathrm{offset}\f$ (a URDF `<mimic>`).
struct JointCoupling {
  int joint = 0;          ///< the model's joint (from 0) that moves chain joint k
  double multiplier = 1;  ///< chain joint value per unit of `joint` (1 for the independent joint itself)
  double offset = 0;      ///< chain joint value at `joint` = 0 [rad or m] (0 for the independent joint itself)
  bool mimic = false;     ///< true: a mimic joint, no joint of the model; false: model joint `joint` itself
};

/// The rotation of a link's fixed placement when it only permutes and flips axes, as a placement
/// whose roll, pitch and yaw are multiples of 90 degrees does (every entry 0 or +-1 to within
/// 8 machine epsilons): column k of the rotation is `sign[k]` times unit vector `axis[k]`. The
/// kinematics then moves the previous frame's columns instead of multiplying by the rotation.
struct PlacementAxes {
  bool permutation = false;            ///< whether the rotation is such a signed permutation
  std::array<int, 3> axis{0, 1, 2};     ///< the unit vector (0 x, 1 y, 2 z) of column k
  std::array<double, 3> sign{1, 1, 1};  ///< its sign (+1 or -1)
};

/// The constant model of a serial manipulator with revolute and prismatic joints: Denavit-Hartenberg
/// (standard or modified) or general-placement (DHConvention::Placement) kinematics, rigid-body
/// dynamics, motor inertia, friction and limits, a base transform (the
/// robot's pose in the world) and a tool transform (end-effector relative to the last link frame).
///
/// A model never changes after construction; algorithms (forwardKinematics(), inverseDynamics(),
/// ...) read it and write into a ManipulatorData made from it, one per thread (the model/data split
/// of Pinocchio and MuJoCo). Built-in robots derive from it: Puma560Model, WAM7Model, WAM4Model.
class ManipulatorModel {
 public:
  /// Creates a model.
  /// @param[in] name        robot name, e.g. `puma560`
  /// @param[in] links       one entry per joint, from the base outwards (1 to kMaxJoints)
  /// @param[in] base        pose of the base frame in the world [m]
  /// @param[in] tool        pose of the end-effector in the last link frame [m]
  /// @param[in] gravity     gravity acceleration in the world frame [m/s^2]
  /// @param[in] convention  DH convention of `links`
  /// @throws std::invalid_argument for 0 or more than kMaxJoints links, a number that is not
  ///         finite, a negative mass, limits with min > max, a placement that is not a rigid
  ///         transform (or one given with a DH convention, or DH parameters given with
  ///         DHConvention::Placement), or two joints or two links of the same name
  ManipulatorModel(std::string name, std::vector<LinkParameters> links, const Transform& base = Transform::unit(),
                   const Transform& tool = Transform::unit(), const Vector<3>& gravity = standardGravity(),
                   DHConvention convention = DHConvention::Standard);
  /// Creates a model of a chain whose mimic joints follow other joints (a URDF `<mimic>` on the
  /// chain): the model's joints are the chain's independent joints, in chain order, and every
  /// algorithm (kinematics, Jacobians, dynamics) works on the full chain at
  /// \f$q^{\mathrm{chain}} = S q + o\f$ and maps back (\f$J S\f$, \f$S^T \tau\f$, \f$S^T M S\f$).
  /// Joint i's LinkParameters are those of its chain joint, with the limits narrowed to what the
  /// mimic joints that follow it allow (positions, speeds, accelerations, jerks), and the mimic
  /// joints' friction and motor inertia reflected onto it (so frictionTorque() and
  /// getArmatureInertia() include them exactly); its mass data is only that of its own chain link
  /// (the algorithms use getChain()).
  /// @param[in] chain     the full chain, every joint a joint of its own (without mimic joints)
  /// @param[in] coupling  one entry per chain joint; the independent ones numbered 0, 1, ... in order
  /// @throws std::invalid_argument for a null chain, a chain with mimic joints, a coupling of the wrong
  ///         size or out of order, no independent joint, a multiplier or offset that is not finite,
  ///         or limits of a mimic joint that leave its master no position
  ManipulatorModel(std::shared_ptr<const ManipulatorModel> chain, std::vector<JointCoupling> coupling);
  virtual ~ManipulatorModel() = default;
  ManipulatorModel(const ManipulatorModel&) = default;             ///< copyable
  ManipulatorModel& operator=(const ManipulatorModel&) = delete;  ///< a model never changes

  /// Gravity of 9.81 m/s^2 along -z.
  static Vector<3> standardGravity() {
    Vector<3> g;
    g(2) = -9.81;
    return g;
  }

  /// Robot name. Real-time safe: yes.
  const std::string& getName() const { return name_; }
  /// Number of joints. Real-time safe: yes.
  int getNumberOfJoints() const { return static_cast<int>(links_->links.size()); }
  /// Parameters of joint/link `i` (from 0). Real-time safe: yes.
  const LinkParameters& getLink(int i) const { return links_->links[static_cast<std::size_t>(i)]; }
  /// DH convention. Real-time safe: yes.
  DHConvention getConvention() const { return convention_; }
  /// Name of joint `i` (from 0): the URDF joint name, or `joint1`, `joint2`, ... Real-time safe: yes.
  const std::string& getJointName(int i) const { return getLink(i).jointName; }
  /// Name of link `i` (from 0), the body joint `i` moves: the URDF link name, or `link1`, ...
  /// Real-time safe: yes.
  const std::string& getLinkName(int i) const { return getLink(i).linkName; }
  /// The joint (from 0) named `name`, or -1. Real-time safe: no.
  /// @param[in] name  a joint name
  int findJoint(const std::string& name) const;
  /// The fixed part \f$P_i\f$ of link `i`'s transform \f$A_i = P_i\,J(q_i)\f$ for the modified DH
  /// (\f$R_x(\alpha) T_x(a) R_z(\mathrm{offset}) T_z(d)\f$) and Placement conventions; for
  /// standard DH, whose fixed parts lie on both sides of the motion, the unit transform.
  /// Real-time safe: yes.
  const Transform& getPlacement(int i) const { return links_->placements[static_cast<std::size_t>(i)]; }
  /// The rotation of getPlacement(i) as a signed permutation of the axes, when it is one (see
  /// PlacementAxes; modified DH and Placement conventions). Real-time safe: yes.
  const PlacementAxes& getPlacementAxes(int i) const { return links_->placementAxes[static_cast<std::size_t>(i)]; }
  /// Whether joint `i` (from 0) is prismatic. Real-time safe: yes.
  bool isPrismatic(int i) const { return getLink(i).type == JointType::Prismatic; }
  /// Pose of the base in the world [m]. Real-time safe: yes.
  const Transform& getBaseTransform() const { return base_; }
  /// Pose of the end-effector in the last link frame [m]. Real-time safe: yes.
  const Transform& getToolTransform() const { return tool_; }
  /// Whether getToolTransform() is exactly the identity (the end-effector frame is the last link
  /// frame; forward kinematics then copies it instead of multiplying). Real-time safe: yes.
  bool hasIdentityTool() const { return toolIsIdentity_; }
  /// Gravity in the world frame [m/s^2]. Real-time safe: yes.
  const Vector<3>& getGravity() const { return gravity_; }

  /// Lower joint limits [rad] (numberOfJoints x 1). Real-time safe: yes.
  const JointVector& getPositionMin() const { return links_->qmin; }
  /// Upper joint limits [rad]. Real-time safe: yes.
  const JointVector& getPositionMax() const { return links_->qmax; }
  /// Joint speed limits [rad/s]. Real-time safe: yes.
  const JointVector& getVelocityLimit() const { return links_->vmax; }
  /// Joint acceleration limits for trajectories [rad/s^2]. Real-time safe: yes.
  const JointVector& getAccelerationLimit() const { return links_->amax; }
  /// Joint jerk limits for trajectories [rad/s^3]. Real-time safe: yes.
  const JointVector& getJerkLimit() const { return links_->jmax; }
  /// Joint torque limits [N m]. Real-time safe: yes.
  const JointVector& getTorqueLimit() const { return links_->taumax; }
  /// Reflected motor inertia \f$G^2 J_m\f$ per joint [kg m^2]. Real-time safe: yes.
  const JointVector& getArmatureInertia() const { return links_->armature; }
  /// Whether `q` lies within the joint limits (inclusive). Real-time safe: yes.
  bool isWithinLimits(const JointVector& q) const;

  /// \f$\cos\alpha_i\f$ of every link (precomputed for the algorithms). Real-time safe: yes.
  const JointVector& getCosAlpha() const { return links_->cosAlpha; }
  /// \f$\sin\alpha_i\f$ of every link (precomputed for the algorithms). Real-time safe: yes.
  const JointVector& getSinAlpha() const { return links_->sinAlpha; }
  /// Link `i`'s rotational inertia about its centre of mass as \f$L L^T\f$, L lower triangular
  /// (its Cholesky factor, precomputed for the mass matrix: \f$R I_c R^T = (R L)(R L)^T\f$ costs
  /// half the products of the plain form), or nullptr where the inertia is not positive definite
  /// (a point mass, a massless link). Real-time safe: yes.
  const Eigen::Matrix3d* getInertiaFactor(int i) const {
    const auto k = static_cast<std::size_t>(i);
    return links_->inertiaFactorValid[k] ? &links_->inertiaFactors[k] : nullptr;
  }

  /// A good resting configuration (the model's home or ready pose) [rad]. Real-time safe: yes.
  const JointVector& getHomePosition() const { return home_; }

  /// Whether the chain has mimic joints (made by the coupling constructor). Real-time safe: yes.
  bool hasMimicJoints() const { return chain_ != nullptr; }
  /// The full chain, mimic joints included as joints of their own; the model itself when it has
  /// no mimic joints. Real-time safe: yes.
  const ManipulatorModel& getChain() const { return chain_ ? *chain_ : *this; }
  /// How each chain joint moves (empty without mimic joints). Real-time safe: yes.
  const std::vector<JointCoupling>& getCoupling() const { return coupling_; }
  /// The chain joint (from 0) of joint `i` (`i` itself without mimic joints). Real-time safe: yes.
  int getChainIndex(int i) const { return chain_ ? chainIndex_[static_cast<std::size_t>(i)] : i; }
  /// The chain's joint values for the model's: \f$q^{\mathrm{chain}} = S q + o\f$ (`offsets` false:
  /// \f$S q\f$, for speeds and accelerations); `q` itself without mimic joints. Real-time safe: yes.
  /// @param[in] q        the model's joint values (numberOfJoints)
  /// @param[out] chainQ  the chain's (getChain().getNumberOfJoints())
  /// @param[in] offsets  whether to add the mimic offsets
  void toChain(const JointVector& q, JointVector& chainQ, bool offsets = true) const;

 protected:
  /// Sets the home configuration (derived models call it in their constructor).
  /// @param[in] q  home joint angles [rad]
  void setHomePosition(const JointVector& q);

 private:
  // What a model's algorithms read of its links every cycle, made once per distinct set of links:
  // models with the same links (every Puma560Model, wherever its base) share one, so many arms
  // of one kind keep a single copy in the caches instead of one per arm (see internLinks()).
  struct Links {
    std::vector<LinkParameters> links;
    std::vector<Transform> placements;
    std::vector<PlacementAxes> placementAxes;
    JointVector qmin, qmax, vmax, amax, jmax, taumax, armature, cosAlpha, sinAlpha;
    std::vector<Eigen::Matrix3d> inertiaFactors;  // Cholesky factors (getInertiaFactor())
    std::vector<bool> inertiaFactorValid;
  };
  static std::shared_ptr<const Links> internLinks(std::shared_ptr<Links> links, DHConvention convention);

  std::string name_;
  std::shared_ptr<const Links> links_;  // never null
  Transform base_, tool_;
  bool toolIsIdentity_ = false;
  Vector<3> gravity_;
  DHConvention convention_;
  JointVector home_;
  std::shared_ptr<const ManipulatorModel> chain_;  // with mimic joints only
  std::vector<JointCoupling> coupling_;
  std::vector<int> chainIndex_;
};

}  // namespace rp
