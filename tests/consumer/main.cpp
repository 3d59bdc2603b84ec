// A program outside the project, built against an installed meccano-immerse only (through the CMake
// package or through pkg-config; see run_consumer.sh), as an FE code would use it.
//
// It inserts a small curved patch into the unit-cube meccano at l_r = 0.125 and checks the result:
// no inverted tet, verify_mesh finds no problem, and the patch is present as interface faces.
// Output  one line per check; exit status 0 if all pass, 1 otherwise (or on any exception).
#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/mesh/invariants.hpp>
#include <meccano/stages/pipeline.hpp>
#include <meccano/surface/validation.hpp>

#include <cmath>
#include <exception>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

namespace {

// z = 0.5 + 0.1 sin(pi u) sin(pi v) over (x, y) = (0.25 + 0.5 u, 0.25 + 0.5 v), u, v in [0, 1]: n x n cells
// of two triangles each, normals towards +z, at least 0.25 from every side of the unit cube.
meccano::TriangleSurface curved_patch(int n) {
  meccano::TriangleSurface patch;
  patch.name = "patch";
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const double u = static_cast<double>(i) / n;
      const double v = static_cast<double>(j) / n;
      const double bump = 0.1 * std::sin(std::numbers::pi * u) * std::sin(std::numbers::pi * v);
      patch.points.emplace_back(0.25 + 0.5 * u, 0.25 + 0.5 * v, 0.5 + bump);
    }
  }
  const auto vertex = [n](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      patch.triangles.push_back({vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1)});
      patch.triangles.push_back({vertex(i, j), vertex(i + 1, j + 1), vertex(i, j + 1)});
    }
  }
  return patch;
}

bool report_check(bool passed, const std::string& what) {
  std::cout << (passed ? "ok      " : "FAILED  ") << what << '\n';
  return passed;
}

}  // namespace

int main() {
  try {
    const meccano::Box unit_cube{Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()};
    const std::vector<meccano::TriangleSurface> surfaces{curved_patch(8)};
    meccano::validate_surfaces(surfaces, unit_cube);

    meccano::InsertionOptions options;
    options.resolution = 0.125;
    const meccano::InsertionResult result =
        meccano::insert_surfaces(meccano::make_cube_meccano(unit_cube), surfaces, options);
    std::cout << result.mesh.num_tets() << " tets, " << result.mesh.num_vertices() << " vertices\n";

    const meccano::MeshInvariantReport check = meccano::verify_mesh(result.mesh);
    std::size_t interface_faces = 0;
    for (const meccano::FaceGroup& group : meccano::output_groups(result).surfaces)
      if (group.name == "interface_patch") interface_faces = group.faces.size();

    bool passed = report_check(result.smoothing.untangled(),
                               std::to_string(result.smoothing.inverted_after) + " inverted tets after smoothing");
    passed &= report_check(check.ok(), "verify_mesh: " + check.summary());
    passed &= report_check(interface_faces > 0, std::to_string(interface_faces) + " faces in interface_patch");
    return passed ? 0 : 1;
  } catch (const std::exception& error) {
    std::cerr << "consumer: " << error.what() << '\n';
    return 1;
  }
}
