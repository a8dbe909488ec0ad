// Rotation behaviour of E and A.
//
// What is tested: E decodes displacements in each triangle's local frame of C, and A's
// field decodes residuals in the local frame of the corrected triangle of C_hat; both
// frames rotate with the mesh. So for a FIXED latent z (given, not computed by H), rotating
// the input positions C by a rigid rotation R (and translating them) must give
//   C_hat(R C + t) = R C_hat(C) + t   and   G(R C + t) = R G(C) + t,
// i.e. the local outputs (E's per-corner displacements, the field's local residuals) are
// invariant and the world outputs equivariant. The full model is not tested this way: H's
// input features (raw velocities, normals, edge vectors in world axes) are not rotation
// invariant, as in the reference.
#include <doctest/doctest.h>

#include "autograd/autograd.hpp"
#include "gdsr/model/gdsr_model.hpp"
#include "gdsr/model/model_config.hpp"
#include "tests/support/model_test_util.hpp"

#include <Eigen/Geometry>
#include <string>

using namespace gdsr;

TEST_CASE("model invariance: E and A outputs rotate with the input (local frames)") {
  ModelConfig cfg = load_model_config(std::string(GDSR_SOURCE_DIR) + "/configs/tiny.json");
  cfg.e_scale_init = 0.3;  // larger outputs: a wrong frame would show clearly
  cfg.field_scale_init = 0.05;
  GDSR<double> model(cfg);
  const GarmentMesh garment = gdsr_test::grid_garment(gdsr_test::GridSpec::square(4, 0.2));
  const GarmentGraph g = build_graph(garment);
  nn::Rng rng(5);
  const FrameInput in = gdsr_test::make_frame(garment.V, rng, 0.02);
  const HrRequest hr = gdsr_test::random_samples(g.num_faces(), 40, rng);
  ag::Tensord z = ag::Tensord::zeros({g.num_vertices, cfg.decoder.back()});
  for (double& v : z.values()) v = rng.normal(0, 1);

  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(rng.uniform(0.3, 3.0),
                        Eigen::Vector3d(rng.normal(0, 1), rng.normal(0, 1), rng.normal(0, 1)).normalized())
          .toRotationMatrix();
  const Eigen::RowVector3d t(0.3, -0.2, 0.5);
  auto transform = [&](const Points3& P) {
    Points3 Q = P * R.transpose();
    Q.rowwise() += t;
    return Q;
  };

  ag::NoGradGuard ng;
  const auto a = model.decode(g, ag::Tensord::from_eigen(in.C_t), z, &hr);
  const auto b = model.decode(g, ag::Tensord::from_eigen(transform(in.C_t)), z, &hr);

  const Points3 C_hat_a = a.C_hat.mat(), C_hat_b = b.C_hat.mat();
  const Points3 G_a = a.G.mat(), G_b = b.G.mat();
  const double d_scale = Points3(a.D.mat()).cwiseAbs().maxCoeff();
  const double r_scale = Points3(a.residual.mat()).cwiseAbs().maxCoeff();
  MESSAGE("max |D| = " << d_scale << " m, max |residual| = " << r_scale << " m");
  REQUIRE(d_scale > 1e-3);  // non-trivial outputs
  REQUIRE(r_scale > 1e-4);
  CHECK((transform(C_hat_a) - C_hat_b).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((transform(G_a) - G_b).cwiseAbs().maxCoeff() < 1e-12);
  // Local outputs are invariant.
  CHECK((Points3(a.residual_local.mat()) - Points3(b.residual_local.mat())).cwiseAbs().maxCoeff() < 1e-12);
  // Residuals (world) rotate without the translation.
  CHECK((Points3(a.residual.mat()) * R.transpose() - Points3(b.residual.mat())).cwiseAbs().maxCoeff() < 1e-12);

  // Sanity of the test itself: decoding with world-axis displacements would not be
  // equivariant, so a mismatch of the same size as D must be detectable: the rotated D
  // differs from the unrotated one.
  CHECK((Points3(a.D.mat()) - Points3(b.D.mat())).cwiseAbs().maxCoeff() > 1e-4);
}
