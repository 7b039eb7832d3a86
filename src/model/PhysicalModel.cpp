// The nearest physical model, as the exports write it (rp/model/PhysicalModel.hpp).
#include "rp/model/PhysicalModel.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "ExportFrames.hpp"

namespace rp {

namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// Second moment of mass about the centre of mass, Sigma = tr(I)/2 - I; back: I = tr(Sigma) - Sigma.
Matrix3d secondMoment(const Matrix3d& I) { return 0.5 * I.trace() * Matrix3d::Identity() - I; }
Matrix3d inertiaOf(const Matrix3d& sigma) { return sigma.trace() * Matrix3d::Identity() - sigma; }

Vector3d principalMoments(const Matrix3d& I) { return Eigen::SelfAdjointEigenSolver<Matrix3d>(I).eigenvalues(); }

std::string triple(const Vector3d& v) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "(%.6g, %.6g, %.6g)", v(0), v(1), v(2));
  return buf;
}

// The joint axis of link k in link frame k's coordinates: z_{k-1} in standard DH (frame k is
// frame k-1 moved by Rz Tz Tx Rx(alpha), so z_{k-1} = (0, sin alpha, cos alpha)), z_k in modified DH.
Vector3d jointAxis(const LinkParameters& l, DHConvention convention) {
  if (convention == DHConvention::Modified) return Vector3d::UnitZ();
  // cos(pi/2) is 6e-17, not 0: snap so that a diagonal tensor stays diagonal.
  const auto snap = [](double c) { return std::abs(c) < 1e-12 ? 0.0 : c; };
  return Vector3d(0, snap(std::sin(l.alpha)), snap(std::cos(l.alpha))).normalized();
}

// Symmetric to rounding (a tensor rotated in floating point, as the URDF loader's, is not exactly).
bool isSymmetric(const Matrix3d& I) {
  return (I - I.transpose()).cwiseAbs().maxCoeff() <= 1e-12 * I.cwiseAbs().maxCoeff();
}

// A tensor as written in the corrections: its principal moments, or its diagonal if it is diagonal.
std::string describe(const Matrix3d& I) {
  const bool diagonal = I(0, 1) == 0 && I(0, 2) == 0 && I(1, 2) == 0;
  return diagonal ? "(Ixx, Iyy, Izz) = " + triple(I.diagonal()) : "principal moments " + triple(principalMoments(I));
}

// Makes a non-physical inertia physical: the nearest positive semi-definite second moment of mass
// (Frobenius norm), Sigma' = Sigma_+, plus the margin. With non-negative principal moments at most
// one eigenvalue of Sigma is negative, and raising it by c adds c (1 - v v^T) to the inertia: a
// thin rod along its eigenvector v, which keeps the moment about v.
Matrix3d physicalInertia(const Matrix3d& I, const Vector3d& jointAxis, std::string& how) {
  const double margin = kExportInertiaMargin * std::abs(I.trace());
  const Eigen::SelfAdjointEigenSolver<Matrix3d> eig(secondMoment(I));
  const Vector3d sigma = eig.eigenvalues();
  const Vector3d clipped = sigma.cwiseMax(margin);
  const int raised = static_cast<int>((clipped.array() > sigma.array()).count());
  if (raised == 1 && sigma(0) < 0) {  // eigenvalues ascend: the first one is the negative one
    const Vector3d v = eig.eigenvectors().col(0);
    const double c = clipped(0) - sigma(0);
    how = "a thin rod added along " +
          (std::abs(v.dot(jointAxis)) > 1 - 1e-9 ? std::string("its joint axis")
                                                 : "the principal axis " + triple(v) + " of the link frame") +
          " (" + internal::brief(c) + " kg m^2 about the axes across it; the moment about the rod's axis is kept)";
  } else {
    how = "inertia added about every axis (the negative part of its second moment of mass removed)";
  }
  return inertiaOf(eig.eigenvectors() * clipped.asDiagonal() * eig.eigenvectors().transpose());
}

}  // namespace

bool isPhysicalInertia(const Matrix<3, 3>& inertia) {
  const Matrix3d I = inertia;
  if (!I.allFinite() || !isSymmetric(I)) return false;
  const Matrix3d symmetric = 0.5 * (I + I.transpose());
  return Eigen::SelfAdjointEigenSolver<Matrix3d>(secondMoment(symmetric), Eigen::EigenvaluesOnly).eigenvalues().minCoeff() >=
         0;
}

PhysicalModel physicalModel(const ManipulatorModel& model) {
  if (model.hasMimicJoints()) {
    std::string mimics;
    for (std::size_t k = 0; k < model.getCoupling().size(); ++k)
      if (model.getCoupling()[k].mimic) mimics += (mimics.empty() ? "'" : ", '") + model.getChain().getJointName(static_cast<int>(k)) + "'";
    throw std::invalid_argument("physicalModel: " + model.getName() + " has mimic joints on its chain (" + mimics +
                                "); exporting them (URDF, MJCF) is not supported");
  }
  const int n = model.getNumberOfJoints();
  std::vector<LinkParameters> links;
  double totalMass = 0, size = 0;
  for (int k = 0; k < n; ++k) {
    const LinkParameters& l = model.getLink(k);
    const std::string where = "physicalModel: " + model.getName() + " link " + std::to_string(k + 1) + ": ";
    if (!std::isfinite(l.mass)) throw std::invalid_argument(where + "the mass is not finite");
    if (!Matrix3d(l.inertia).allFinite()) throw std::invalid_argument(where + "the inertia is not finite");
    if (!Vector3d(l.com).allFinite()) throw std::invalid_argument(where + "the centre of mass is not finite");
    links.push_back(l);
    totalMass += l.mass;
    size += std::abs(l.a) + std::abs(l.d);
  }
  if (!std::isfinite(size) || size == 0) size = 1;
  std::vector<ModelCorrection> corrections;
  for (int k = 0; k < n; ++k) {
    LinkParameters& l = links[static_cast<std::size_t>(k)];
    const std::string name = "link " + std::to_string(k + 1) + ": ";
    Matrix3d I = Matrix3d(l.inertia);
    if (!isSymmetric(I)) {
      const Matrix3d symmetric = 0.5 * (I + I.transpose());
      corrections.push_back({k, name + "the inertia tensor is not symmetric; its symmetric part is written"});
      I = symmetric;
      l.inertia = I;
    }
    if (!isPhysicalInertia(l.inertia)) {
      std::string how;
      const Matrix3d fixed = physicalInertia(I, jointAxis(l, model.getConvention()), how);
      corrections.push_back({k, name + "the inertia " + describe(I) +
                                    " is not that of a rigid body (its principal moments break the triangle "
                                    "inequality Ia + Ib >= Ic); written as " + describe(fixed) + ", with " + how});
      I = fixed;
      l.inertia = I;
    }
    if (totalMass > 0 && l.mass < kExportMassFloor * totalMass) {
      const double m = kExportMassFloor * totalMass;
      corrections.push_back({k, name + "the mass " + internal::brief(l.mass) + " kg is too small for a moving body; written as " +
                                    internal::brief(m) + " kg (" + internal::brief(kExportMassFloor) +
                                    " of the arm's) at its centre of mass"});
      l.mass = m;
    }
    const double floor = kExportInertiaFloor * totalMass * size * size;
    const double smallest = principalMoments(I).minCoeff();
    if (totalMass > 0 && smallest < floor) {
      corrections.push_back({k, name + "the smallest principal moment " + internal::brief(smallest) +
                                    " kg m^2 is too small for a moving body; raised to " + internal::brief(floor) +
                                    " kg m^2 (an isotropic term, " + internal::brief(kExportInertiaFloor) + " m L^2)"});
      I += (floor - smallest) * Matrix3d::Identity();
      l.inertia = I;
    }
  }
  return {ManipulatorModel(model.getName(), std::move(links), model.getBaseTransform(), model.getToolTransform(),
                           model.getGravity(), model.getConvention()),
          std::move(corrections)};
}

}  // namespace rp
