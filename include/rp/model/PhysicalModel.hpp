#pragma once
/// @file
/// The nearest physical model of a manipulator: the inertial data the URDF and MJCF exports write,
/// so that simulators that check it (MuJoCo, Drake) load every model.

#include <string>
#include <vector>

#include "rp/model/ManipulatorModel.hpp"

namespace rp {

/// Smallest mass of an exported link, as a fraction of the arm's total mass: a link with less
/// (none, as the Puma 560's link 1) gets this much at its centre of mass.
inline constexpr double kExportMassFloor = 1e-9;

/// Smallest principal moment of an exported link, as a fraction of \f$m L^2\f$ (total mass, the
/// arm's size \f$L = \sum_k |a_k| + |d_k|\f$, 1 m if zero).
inline constexpr double kExportInertiaFloor = 1e-9;

/// Margin added to a corrected inertia, as a fraction of its trace, so that a simulator's own
/// rounding (MuJoCo diagonalises the tensor again) still finds it physical.
inline constexpr double kExportInertiaMargin = 1e-9;

/// One change physicalModel() made to a link.
struct ModelCorrection {
  int link = 0;             ///< link (and joint) index, from 0
  std::string description;  ///< what was wrong and what the export writes instead, one sentence
};

/// A model whose links all have physical inertial data, and what was changed to get it.
struct PhysicalModel {
  ManipulatorModel model;                    ///< the corrected model (the same kinematics, drives, friction and limits)
  std::vector<ModelCorrection> corrections;  ///< one entry per change, empty when the model was physical
};

/// Whether `inertia` (about the centre of mass) is the inertia of a rigid body: symmetric, finite,
/// and its principal moments satisfy the triangle inequality \f$I_a + I_b \ge I_c\f$ (which makes
/// them non-negative), i.e. the second moment of mass \f$\Sigma = \tfrac12 \mathrm{tr}(I)\,1 - I\f$
/// is positive semi-definite.
/// @param[in] inertia  inertia tensor [kg m^2]
/// @return true if physical
/// Real-time safe: yes.
bool isPhysicalInertia(const Matrix<3, 3>& inertia);

/// The model as the URDF and MJCF exports write it (toUrdf(), exportMjcf()).
///
/// A link whose inertia breaks the triangle inequality (published values such as the Puma 560's
/// link 3, (0.066, 0.086, 0.0125) kg m^2, are not those of any rigid body) gets the nearest
/// physical inertia in terms of the second moment of mass: \f$\Sigma' = \Sigma_+\f$, the
/// positive semi-definite part of \f$\Sigma\f$ (the nearest in the Frobenius norm), plus
/// kExportInertiaMargin of the trace. With non-negative principal moments only one eigenvalue
/// \f$-c\f$ of \f$\Sigma\f$ can be negative, and the change is then \f$c\,(1 - v v^T)\f$: a thin
/// rod along its eigenvector \f$v\f$, which keeps the moment about \f$v\f$. Inertia is only ever
/// added. For the Puma's links 1 and 3, \f$v\f$ is the joint axis: link 1 becomes (0.175, 0.35,
/// 0.175), which changes no joint torque of a fixed arm, and link 3 (0.06975, 0.086, 0.01625).
/// Then, if the arm has mass at all, a link lighter than kExportMassFloor of the arm's mass gets
/// that mass at its centre of mass (the Puma's link 1 has none; its centre lies on joint 1's axis,
/// so again no joint torque changes), and a principal moment below kExportInertiaFloor \f$m L^2\f$
/// is raised to it (an isotropic term). Links that are physical and heavy enough are left exactly
/// as they are (an asymmetry of rounding size, 1e-12 of the largest element, is accepted).
/// @param[in] model  the manipulator
/// @return the corrected model and the list of corrections
/// @throws std::invalid_argument for a model with mimic joints (ManipulatorModel::hasMimicJoints()),
///         and naming the link for an inertia, mass or centre of mass that is
///         not finite
/// Real-time safe: no.
PhysicalModel physicalModel(const ManipulatorModel& model);

}  // namespace rp
