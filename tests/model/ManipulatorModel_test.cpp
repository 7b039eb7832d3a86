// ManipulatorModel: models with the same links share one copy of what the algorithms read of them
// (issue 21: a hundred Pumas in one executor read one set of link parameters, not a hundred),
// and sharing changes no result.
#include <gtest/gtest.h>

#include <memory>
#include <thread>
#include <vector>

#include "rp/model/Dynamics.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/ManipulatorData.hpp"
#include "rp/model/Puma560Model.hpp"
#include "rp/model/WAMModel.hpp"

namespace rp {
namespace {

// The Puma's links as a model of its own, with joint 6 renamed so that it shares nothing with a
// Puma560Model: the reference the shared model's results are compared with.
ManipulatorModel unsharedPuma(const Transform& base) {
  const Puma560Model puma;
  std::vector<LinkParameters> links;
  for (int i = 0; i < puma.getNumberOfJoints(); ++i) links.push_back(puma.getLink(i));
  links[5].jointName = "wrist_roll";
  return ManipulatorModel("unshared", links, base, puma.getToolTransform(), puma.getGravity(), puma.getConvention());
}

TEST(ManipulatorModelLinks, ModelsWithTheSameLinksShareThemWhereverTheirBase) {
  const Puma560Model a(0.67183, translation(0.5, 0, 0)), b(0.67183, translation(-0.5, 1, 0) * rpyToTransform(0, 0, 1));
  EXPECT_EQ(&a.getLink(0), &b.getLink(0)) << "two Pumas hold two copies of the same links";
  EXPECT_EQ(&a.getCosAlpha(), &b.getCosAlpha());
  EXPECT_EQ(&a.getPositionMax(), &b.getPositionMax());
  // What differs stays each model's own.
  EXPECT_NE(a.getBaseTransform()(0, 3), b.getBaseTransform()(0, 3));

  // Other links: not shared. A different pedestal, another robot, a renamed joint.
  const Puma560Model low(0.0);
  EXPECT_NE(&a.getLink(0), &low.getLink(0));
  EXPECT_EQ(low.getLink(0).d, 0.0);
  EXPECT_EQ(a.getLink(0).d, 0.67183);
  const WAM7Model wam;
  EXPECT_NE(&a.getLink(0), &wam.getLink(0));
  const ManipulatorModel renamed = unsharedPuma(translation(0.5, 0, 0));
  EXPECT_NE(&a.getLink(0), &renamed.getLink(0));
  EXPECT_EQ(renamed.getJointName(5), "wrist_roll");
  EXPECT_EQ(a.getJointName(5), "joint6");
}

TEST(ManipulatorModelLinks, ASharedModelComputesAsAModelOfItsOwn) {
  // Kinematics, the mass matrix and the inverse dynamics of a Puma sharing its links with another
  // are those of a model of its own with the same parameters, to the last bit.
  const Transform base = translation(0.5, 0.2, 0) * rpyToTransform(0, 0, 0.3);
  const Puma560Model other(0.67183, translation(3, 0, 0));
  const Puma560Model shared(0.67183, base);
  ASSERT_EQ(&other.getLink(0), &shared.getLink(0));
  const ManipulatorModel own = unsharedPuma(base);
  ASSERT_NE(&own.getLink(0), &shared.getLink(0));
  ManipulatorData ds(shared), dn(own);
  JointVector q(6), qd(6), qdd(6);
  q << 0.1, -0.7, 0.4, 1.2, -0.5, 0.9;
  qd << 0.3, -0.2, 0.5, 1.0, -1.5, 2.0;
  qdd << -1, 2, 0.5, 3, -2, 1;
  EXPECT_EQ(forwardKinematics(shared, ds, q), forwardKinematics(own, dn, q));
  massMatrix(shared, ds, q);
  massMatrix(own, dn, q);
  EXPECT_EQ(ds.massMatrix, dn.massMatrix);
  EXPECT_EQ(inverseDynamics(shared, ds, q, qd, qdd), inverseDynamics(own, dn, q, qd, qdd));
}

TEST(ManipulatorModelLinks, SharedLinksLiveAsLongAsTheirLastModel) {
  auto first = std::make_unique<Puma560Model>();
  auto second = std::make_unique<Puma560Model>(0.67183, translation(1, 0, 0));
  const LinkParameters* links = &second->getLink(0);
  ASSERT_EQ(links, &first->getLink(0));
  first.reset();  // the second model's links stay (AddressSanitizer checks the reads below)
  EXPECT_EQ(second->getLink(2).a, links[2].a);
  ManipulatorData data(*second);
  JointVector q = second->getHomePosition();
  EXPECT_TRUE(forwardKinematics(*second, data, q).allFinite());
  const Puma560Model third;
  EXPECT_EQ(&third.getLink(0), links) << "a new model shares the links still in use";
}

TEST(ManipulatorModelLinks, ModelsMadeInManyThreadsAtOnceShareOneCopy) {
  // Arms are made from several threads (a program's objects, a test's, the configuration's): the
  // registry of links is safe for that (ThreadSanitizer runs this, label "threads").
  std::vector<std::unique_ptr<Puma560Model>> models(8);
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < models.size(); ++t)
    threads.emplace_back([&models, t] {
      for (int i = 0; i < 20; ++i) models[t] = std::make_unique<Puma560Model>(0.67183, translation(static_cast<double>(t), 0, 0));
    });
  for (std::thread& t : threads) t.join();
  for (const auto& m : models) EXPECT_EQ(&m->getLink(0), &models[0]->getLink(0));
}

}  // namespace
}  // namespace rp
