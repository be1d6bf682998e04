// The per-face fracture stress sigma+ (paper Eq. 1, 2, 8) against closed forms.
//
// Membrane: a flat sheet stretched by a factor s along x has F_el = diag(s, 1) and Green strain
// G = diag((s^2 - 1)/2, 0); with nu = 0 the stress is k_s G (k_s = E h), tensile only.
//
// Curvature: II = sym(F^T grad n). A cylinder of radius R whose world nodes sit exactly on the circle, with the
// arc angle between columns chosen so that every grid edge keeps its rest length, has an isometric F and
// (by the grid's point symmetry about each interior node) exactly radial vertex normals n = P(x - axis)/R with
// P the projection off the axis: grad n = P F / R, so II = F^T P F / R = diag(+-1/R, 0) exactly on faces away
// from the border (the sign: + when the normals point away from the axis). A sphere gives II = F^T F / R,
// i.e. 1/R up to the cap's small stretch.
//
// Bending fracture (Eq. 8): on that isometric cylinder F_el^T F_el = I and II* = diag(1/R, 0), so with
// a = 1/2 alpha h / R
//   F_B^T F_B = (I + a e1 e1^T)^2,   G = ((1 + a)^2 - 1)/2 e1 e1^T = (a + a^2/2) e1 e1^T,
//   sigma = (k11 G11, k12 G11) on the diagonal: k_s (a + a^2/2) and k_s nu (a + a^2/2).
#include "fracture/fracture_stress.hpp"

#include <gtest/gtest.h>

#include <omp.h>

#include <cmath>

#include "physics/face_element.hpp"
#include "plasticity/plastic_tensors.hpp"
#include "support/eigenvalues.hpp"
#include "support/mesh_factory.hpp"

namespace arcsim {
namespace {

using testing::Diagonal;
using testing::make_grid;
using testing::symmetric_eigenvalues;

constexpr double kThickness = 1e-3;  // m
constexpr double kYoung = 2e9;       // Pa

std::vector<Material> breakable(double nu = 0, double alpha = 0) {
  Material m;
  m.thickness = kThickness;
  m.density = 1000;
  m.youngs_modulus = kYoung;
  m.poisson_ratio = nu;
  m.toughness = 1e6;
  m.fracture_bending_mult = alpha;
  return {m};
}

Mesh sheet(int n, double size, Diagonal diagonal = Diagonal::kForward, double x0 = 0, double y0 = 0) {
  Mesh mesh = make_grid(n, n, size, size, diagonal, x0, y0);
  for (Face& f : mesh.faces) f.thickness = kThickness;
  return mesh;
}

Vec3 rest_of(const Mesh& mesh, int node) { return mesh.verts[mesh.nodes[node].verts[0]].u; }

// Bends a flat grid over [0, width] (cells of width dx along x) onto a cylinder of radius R about an axis along
// y, isometrically for every grid edge: consecutive columns are one chord dx apart. direction +1 bends towards
// +z (the rest normal side), -1 away from it.
void bend_onto_cylinder(Mesh& mesh, double dx, double R, double direction) {
  const double step = 2 * std::asin(dx / (2 * R));
  for (size_t n = 0; n < mesh.nodes.size(); ++n) {
    const Vec3 u = rest_of(mesh, static_cast<int>(n));
    const double angle = std::round(u.x() / dx) * step;
    mesh.nodes[n].x = Vec3(R * std::sin(angle), u.y(), direction * R * (1 - std::cos(angle)));
  }
}

bool is_interior_face(const Mesh& mesh, int f) {
  for (int i = 0; i < 3; ++i)
    if (mesh.is_boundary_node(mesh.face_node(f, i))) return false;
  return true;
}

Vec2 eigenvalues(const Mat2& A) { return symmetric_eigenvalues<2>(0.5 * (A + A.transpose())); }

Mat2 curvature(const Mesh& mesh, int f) {
  return face_elastic_curvature(mesh, f, world_node_normals(mesh), rest_vert_normals(mesh));
}

TEST(FractureStress, UniaxialTensionIsStiffnessTimesGreenStrain) {
  Mesh mesh = sheet(3, 1.0, Diagonal::kAlternating);
  const double s = 1.02;
  for (Node& n : mesh.nodes) n.x.x() *= s;
  const auto stress = fracture_stresses(mesh, breakable());
  const double expected = kYoung * kThickness * 0.5 * (s * s - 1);  // k_s G11, nu = 0
  for (const FaceFractureStress& f : stress) {
    EXPECT_NEAR(f.sigma(0, 0), expected, 1e-9 * expected);
    EXPECT_NEAR(f.sigma(1, 1), 0, 1e-9 * expected);
    EXPECT_NEAR(f.sigma(0, 1), 0, 1e-9 * expected);
    EXPECT_NEAR(f.lambda_max, expected, 1e-9 * expected);
  }
}

TEST(FractureStress, CompressionNeverBreaks) {
  Mesh mesh = sheet(3, 1.0);
  for (Node& n : mesh.nodes) n.x = Vec3(0.97 * n.x.x(), 0.99 * n.x.y(), 0);
  for (const FaceFractureStress& f : fracture_stresses(mesh, breakable(0.3))) {
    EXPECT_EQ(f.lambda_max, 0);
    EXPECT_LT(f.sigma.norm(), 1e-9);
  }
}

// Tension along x, compression along y (nu = 0): only the tensile eigenvector survives.
TEST(FractureStress, KeepsOnlyTheTensilePart) {
  Mesh mesh = sheet(2, 1.0);
  for (Node& n : mesh.nodes) n.x = Vec3(1.01 * n.x.x(), 0.98 * n.x.y(), 0);
  const double ks = kYoung * kThickness;
  for (const FaceFractureStress& f : fracture_stresses(mesh, breakable())) {
    EXPECT_NEAR(f.sigma(0, 0), ks * 0.5 * (1.01 * 1.01 - 1), 1e-9 * ks);
    EXPECT_NEAR(f.sigma(1, 1), 0, 1e-12 * ks);
  }
}

TEST(FractureStress, StressUsesTheElasticDeformation) {
  Mesh mesh = sheet(2, 1.0);
  for (Node& n : mesh.nodes) n.x.x() *= 1.2;
  Mat2 Fp2 = Mat2::Identity();
  Fp2(0, 0) = 1 / 1.1;  // F_el = F Fp: the plastic flow has absorbed a stretch of 1.1
  for (Face& f : mesh.faces) f.Fp = face_plastic_stretch_3d(f, Fp2);
  const double s = 1.2 / 1.1;
  const double expected = kYoung * kThickness * 0.5 * (s * s - 1);
  for (const FaceFractureStress& f : fracture_stresses(mesh, breakable()))
    EXPECT_NEAR(f.lambda_max, expected, 1e-9 * expected);
  Fp2(0, 0) = 1 / 1.2;  // all of it plastic: no stress
  for (Face& f : mesh.faces) f.Fp = face_plastic_stretch_3d(f, Fp2);
  for (const FaceFractureStress& f : fracture_stresses(mesh, breakable())) EXPECT_LT(f.lambda_max, 1e-6);
}

TEST(FractureStress, DamageWeakensTheStress) {
  Mesh mesh = sheet(2, 1.0);
  for (Node& n : mesh.nodes) n.x.x() *= 1.01;
  std::vector<Material> materials = breakable();
  materials[0].weakening = 1;
  const double plain = fracture_stresses(mesh, materials)[0].lambda_max;
  mesh.faces[0].damage = 1;
  EXPECT_NEAR(fracture_stresses(mesh, materials)[0].lambda_max, plain / 2, 1e-12 * plain);
}

TEST(FractureStress, UnbreakableAndDeadFacesGetZero) {
  Mesh mesh = sheet(2, 1.0);
  for (Node& n : mesh.nodes) n.x.x() *= 1.1;
  std::vector<Material> materials = breakable();
  materials.push_back(materials[0]);
  materials[1].toughness = 0;
  mesh.faces[1].material = 1;
  mesh.remove_face(2);
  const auto stress = fracture_stresses(mesh, materials);
  ASSERT_EQ(stress.size(), mesh.faces.size());
  EXPECT_GT(stress[0].lambda_max, 0);
  EXPECT_EQ(stress[1].lambda_max, 0);
  EXPECT_EQ(stress[2].lambda_max, 0);
  EXPECT_TRUE(stress[1].sigma.isZero(0));
}

// Bends a 16 x 16 sheet 0.4 m wide onto a cylinder of radius 0.5 m, towards its normal side and away, and checks
// the curvature `measure` gives on every face `keep` accepts: -direction / R across the axis (within
// `tolerance` / R; bending towards the normal side turns the normals towards the axis), 0 along it (1e-6 / R).
template <class Measure, class Keep>
void expect_cylinder_curvature(Measure measure, Keep keep, double tolerance, int min_checked) {
  const double R = 0.5, size = 0.4;
  const int n = 16;
  for (double direction : {1.0, -1.0}) {
    Mesh mesh = sheet(n, size);
    bend_onto_cylinder(mesh, size / n, R, direction);
    int checked = 0;
    for (size_t f = 0; f < mesh.faces.size(); ++f) {
      if (!keep(mesh, static_cast<int>(f))) continue;
      const Mat2 II = measure(mesh, static_cast<int>(f));
      EXPECT_NEAR(II(0, 0), -direction / R, tolerance / R) << "face " << f;
      EXPECT_NEAR(II(1, 1), 0, 1e-6 / R) << "face " << f;
      EXPECT_NEAR(II(0, 1), 0, 1e-6 / R) << "face " << f;
      ++checked;
    }
    EXPECT_GT(checked, min_checked);
  }
}

TEST(FractureStress, CylinderCurvatureIsOneOverRadiusAcrossTheAxis) {
  expect_cylinder_curvature([](const Mesh& mesh, int f) { return curvature(mesh, f); },
                            [](const Mesh& mesh, int f) { return is_interior_face(mesh, f); }, 1e-6, 300);
}

TEST(FractureStress, SphereCurvatureIsOneOverRadiusInEveryDirection) {
  const double R = 1.0, a = 0.1;
  Mesh mesh = sheet(20, 2 * a, Diagonal::kAlternating, -a, -a);
  for (Node& node : mesh.nodes) {  // a dome over the rest plane: normals point away from the centre
    const Vec3 u = node.x;
    node.x.z() = std::sqrt(R * R - u.x() * u.x() - u.y() * u.y()) - R;
  }
  int checked = 0;
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Mat2 II = curvature(mesh, static_cast<int>(f));
    const Vec3 c = (rest_of(mesh, mesh.face_node(static_cast<int>(f), 0)) +
                    rest_of(mesh, mesh.face_node(static_cast<int>(f), 1)) +
                    rest_of(mesh, mesh.face_node(static_cast<int>(f), 2))) / 3;
    if (c.norm() > 0.5 * a) continue;
    const Vec2 l = eigenvalues(II);
    EXPECT_NEAR(l(0), 1 / R, 0.02 / R);
    EXPECT_NEAR(l(1), 1 / R, 0.02 / R);
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

// A shell that rests in its curved shape (a glass sphere) is not bent at all.
TEST(FractureStress, CurvedRestShapeHasNoElasticCurvature) {
  const double R = 1.0, a = 0.3;
  Mesh flat = sheet(12, 2 * a, Diagonal::kAlternating, -a, -a);
  std::vector<Vec3> x;
  std::vector<Vec3> u;
  std::vector<int> vert_node;
  for (const Node& node : flat.nodes) {
    const double z = std::sqrt(R * R - node.x.squaredNorm()) - R;
    x.emplace_back(node.x.x(), node.x.y(), z);
    vert_node.push_back(static_cast<int>(u.size()));
    u.push_back(x.back());
  }
  std::vector<std::array<int, 3>> tris;
  for (const Face& f : flat.faces) tris.push_back({f.v[0], f.v[1], f.v[2]});
  Mesh dome = Mesh::from_triangles(x, u, vert_node, tris);
  for (Face& f : dome.faces) f.thickness = kThickness;
  for (size_t f = 0; f < dome.faces.size(); ++f)
    EXPECT_LT(curvature(dome, static_cast<int>(f)).norm(), 1e-9 / R);
  // And none of it breaks, however strong the bending term.
  for (const FaceFractureStress& s : fracture_stresses(dome, breakable(0.3, 10))) EXPECT_LT(s.lambda_max, 1e-3);
}

// A sheet bent plastically (rest angles = its world dihedrals) and resting in that shape is not bent elastically;
// bent the other way from its plastic shape it is bent twice as much.
TEST(FractureStress, PlasticCurvatureIsSubtracted) {
  const double R = 0.5, size = 0.4;
  const int n = 16;
  Mesh mesh = sheet(n, size);
  bend_onto_cylinder(mesh, size / n, R, 1);
  for (size_t e = 0; e < mesh.edges.size(); ++e) mesh.edges[e].rest_theta = mesh.world_dihedral(static_cast<int>(e));
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    if (!is_interior_face(mesh, static_cast<int>(f))) continue;
    EXPECT_LT(curvature(mesh, static_cast<int>(f)).norm(), 0.02 / R);
  }
  for (size_t e = 0; e < mesh.edges.size(); ++e) mesh.edges[e].rest_theta *= -1;
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    if (!is_interior_face(mesh, static_cast<int>(f))) continue;
    EXPECT_NEAR(curvature(mesh, static_cast<int>(f))(0, 0), -2 / R, 0.04 / R);
  }
}

// A sheet with bending plasticity (its plastic rest angles on the hinges) measures its elastic curvature on the
// hinges too: bent plastically and resting in that shape it reads no bending anywhere, on the faces along its
// border (a crack's lips are border faces) too. Regression: the derivative of the node normals minus the plastic
// hinges' tensor disagreed on border faces (a border node's normal averages one side only, a border edge has no
// plastic hinge); after the first openings in the plastically folded tube of paper Fig. 9 its new crack lips read
// elastic curvatures of 1e3 1/m (s / tau up to 40 on lip faces) and cracked on in parallel slivers.
TEST(FractureStress, PlasticallyBentBorderFacesAreNotBent) {
  const double R = 0.05, size = 0.04;
  const int n = 16;
  for (Diagonal diagonal : {Diagonal::kForward, Diagonal::kAlternating}) {
    Mesh mesh = sheet(n, size, diagonal);
    bend_onto_cylinder(mesh, size / n, R, 1);
    for (size_t e = 0; e < mesh.edges.size(); ++e) mesh.edges[e].rest_theta = mesh.world_dihedral(static_cast<int>(e));
    std::vector<Material> materials = breakable(0.3, 1);
    materials[0].yield_curv = 1 / R;  // bending plasticity: the hinge measure
    const auto stress = fracture_stresses(mesh, materials);
    int border = 0;
    for (size_t f = 0; f < mesh.faces.size(); ++f) {
      if (is_interior_face(mesh, static_cast<int>(f))) continue;
      ++border;
      EXPECT_LT(face_hinge_elastic_curvature(mesh, static_cast<int>(f)).norm(), 1e-9 / R) << "face " << f;
      EXPECT_LT(stress[f].lambda_max, 1e-6 * kYoung * kThickness) << "face " << f;
    }
    EXPECT_GT(border, 4 * n);
  }
}

// The hinge measure's curvature of an elastic bend: 1 / R across the axis on faces away from the border (a free
// edge carries no hinge angle), to the chord's (dx / R)^2 / 24 = 1e-4 relative.
TEST(FractureStress, HingeCurvatureIsOneOverRadiusAcrossTheAxis) {
  const auto deep = [](const Mesh& mesh, int f) {
    for (int i = 0; i < 3; ++i)
      for (int g : mesh.verts[mesh.faces[f].v[i]].faces)
        if (!is_interior_face(mesh, g)) return false;
    return true;
  };
  expect_cylinder_curvature([](const Mesh& mesh, int f) { return face_hinge_elastic_curvature(mesh, f); }, deep,
                            1e-3, 250);
}

TEST(FractureStress, BendingFractureStressOfAnArc) {
  const double R = 0.05, size = 0.04, alpha = 2;
  const int n = 16;
  const double a = 0.5 * alpha * kThickness / R;  // 0.02
  const double G11 = a + 0.5 * a * a;
  for (double nu : {0.0, 0.3}) {
    Mesh mesh = sheet(n, size);
    bend_onto_cylinder(mesh, size / n, R, -1);
    const std::vector<Material> materials = breakable(nu, alpha);
    const double ks = kYoung * kThickness / (1 - nu * nu);
    const auto stress = fracture_stresses(mesh, materials);
    for (size_t f = 0; f < mesh.faces.size(); ++f) {
      if (!is_interior_face(mesh, static_cast<int>(f))) continue;
      EXPECT_NEAR(stress[f].sigma(0, 0), ks * G11, 1e-6 * ks * G11);
      EXPECT_NEAR(stress[f].sigma(1, 1), ks * nu * G11, 1e-6 * ks * G11);
      EXPECT_NEAR(stress[f].sigma(0, 1), 0, 1e-6 * ks * G11);
      EXPECT_NEAR(stress[f].lambda_max, ks * G11, 1e-6 * ks * G11);
    }
    // Without the bending term the isometric bend carries no stress at all.
    std::vector<Material> membrane_only = materials;
    membrane_only[0].fracture_bending_mult = 0;
    for (const FaceFractureStress& s : fracture_stresses(mesh, membrane_only)) EXPECT_LT(s.lambda_max, 1e-9 * ks);
  }
}

TEST(FractureStress, SubsetUpdateMatchesTheFullEvaluation) {
  Mesh mesh = sheet(6, 0.3, Diagonal::kAlternating);
  for (Node& node : mesh.nodes)
    node.x = Vec3(1.03 * node.x.x() + 0.01 * node.x.y(), node.x.y(), 0.2 * node.x.x() * node.x.x());
  const std::vector<Material> materials = breakable(0.25, 1.5);
  const auto full = fracture_stresses(mesh, materials);
  const auto normals = world_node_normals(mesh);
  const auto rest_normals = rest_vert_normals(mesh);
  std::vector<FaceFractureStress> partial(3);
  update_fracture_stresses(mesh, materials, {4, 17, 30}, partial);
  ASSERT_EQ(partial.size(), mesh.faces.size());
  for (int f : {4, 17, 30}) {
    const FaceFractureStress one = face_fracture_stress(mesh, materials, f, normals, rest_normals);
    EXPECT_EQ(partial[f].sigma, full[f].sigma);
    EXPECT_EQ(one.sigma, full[f].sigma);
    EXPECT_EQ(one.lambda_max, full[f].lambda_max);
  }
  EXPECT_EQ(partial[5].lambda_max, 0);
  EXPECT_GT(full[5].lambda_max, 0);
}

TEST(FractureStress, SameResultOnAnyThreadCount) {
  Mesh mesh = sheet(12, 0.3, Diagonal::kAlternating);
  for (Node& node : mesh.nodes)
    node.x = Vec3(1.02 * node.x.x(), node.x.y() + 0.01 * node.x.x(), 0.5 * node.x.y() * node.x.y());
  const std::vector<Material> materials = breakable(0.3, 2);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const auto serial = fracture_stresses(mesh, materials);
  omp_set_num_threads(std::max(threads, 3));
  const auto parallel = fracture_stresses(mesh, materials);
  omp_set_num_threads(threads);
  ASSERT_EQ(serial.size(), parallel.size());
  for (size_t f = 0; f < serial.size(); ++f) {
    EXPECT_EQ(serial[f].sigma, parallel[f].sigma);
    EXPECT_EQ(serial[f].lambda_max, parallel[f].lambda_max);
  }
}

TEST(FractureStress, ToughnessAndRestSpaceStress) {
  Mesh mesh = sheet(1, 1.0);
  Face& face = mesh.faces[0];
  face.thickness = 2e-3;
  EXPECT_DOUBLE_EQ(face_toughness(face, breakable()[0]), 1e6 * 2e-3);
  Mat2 sigma;
  sigma << 3, 1, 1, 2;
  const Mat3 S = stress_to_rest(face, sigma);  // flat xy sheet: frame = (x, y)
  EXPECT_NEAR(S(0, 0), 3, 1e-15);
  EXPECT_NEAR(S(0, 1), 1, 1e-15);
  EXPECT_NEAR(S(1, 1), 2, 1e-15);
  EXPECT_NEAR(S(2, 2), 0, 1e-15);
}

}  // namespace
}  // namespace arcsim
