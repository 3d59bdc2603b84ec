// The catalogue of bad inputs (issue 10): every case, its expected error, and the test that checks it.
// Cases tested elsewhere are listed here; the ones below are tested in this file.
//
// | case                                   | expected message (excerpt)                           | test                                                  |
// |----------------------------------------|------------------------------------------------------|-------------------------------------------------------|
// | empty file (every surface format)      | "FILE: empty file"                                   | SurfaceIo.EmptyFile (test_surface_io)                 |
// | empty mesh file (check)                | "FILE: empty file"                                   | Check.ReaderErrorsNameTheFileThePlaceAndTheDefect     |
// | truncated binary STL                   | "binary STL header announces 32 triangles", "truncated file" | SurfaceIo.StlTruncatedBinary                  |
// | truncated binary / text MSH            | "byte N: ... truncated binary data", "unexpected end of file" | SurfaceIo.MshTruncatedBinary, Check.ReaderErrors... |
// | absurd counts in headers               | "header announces 4294967295 triangles"              | SurfaceIo.StlAbsurdTriangleCount, OffAbsurdCounts,    |
// |                                        | "absurd node count N: cannot fit in the B bytes"     | MshAbsurdCounts, Check.ReaderErrors...                |
// | NaN coordinates                        | "non-finite coordinate"                              | SurfaceIo.ObjNonFiniteCoordinate, StlBinaryNonFinite- |
// |                                        |                                                      | Coordinate, MshNonFiniteCoordinate; SurfaceTopology.  |
// |                                        |                                                      | NonFiniteCoordinate; Check.ReaderErrors...            |
// | out-of-range indices                   | "vertex index 9 out of range (1..3)"                 | SurfaceIo.ObjIndexOutOfRange, OffIndexOutOfRange,     |
// |                                        | "node N is not defined in $Nodes"                    | MshUndefinedNode; SurfaceTopology.IndexOutOfRange;    |
// |                                        |                                                      | Check.ReaderErrors...                                 |
// | closed surface of genus above 0        | "closed surface of genus 1"                          | SurfaceTopology.ClosedSurfacesOfGenusZeroPass...;     |
// |                                        |                                                      | ClosedSurface.ATorusIsRefused                         |
// | surface crossing the box boundary      | "vertex 11 (...) is outside the box [0, 1] x ..."    | GeometryChecks.SurfaceOutsideTheBox; CliTest.BadSurfa-|
// |                                        |                                                      | cesFailWithTheirOwnMessageAndWriteNothing             |
// | surface touching the box boundary      | "on the box boundary"                                | GeometryChecks.VertexOnTheBoxBoundary; CliTest.BadSu..|
// | intersecting / touching surfaces       | "intersect", "touch"                                 | GeometryChecks.CrossingSurfacesIntersect, TouchingSur-|
// |                                        |                                                      | facesTouch; CliTest.BadSurfacesFail...                |
// | self-intersecting surface              | "intersects itself" (triangles named 1-based)        | GeometryChecks.SheetPassingThroughItselfIntersects,   |
// |                                        |                                                      | FoldedOverTrianglesIntersect                          |
// | degenerate triangles                   | "zero area", "repeats vertex"                        | SurfaceTopology.ZeroAreaTriangle, RepeatedVertex      |
// | l_r <= 0 (command line)                | "--resolution must be positive" (exit 2)             | CliTest.UsageErrorsExitTwoWithAMessage                |
// | l_r <= 0 or NaN (library)              | "the resolution l_r must be positive"                | BadInput.NonPositiveResolutionIsRefusedByTheLibrary   |
// | l_r too small for memory               | "would make about ... tets (about ... GiB of memory), above the limit" | BadInput.ATinyResolutionIsRefusedBefore-  |
// |                                        |                                                      | Refining, BadInput.TheLimitIsOverridable, BadInput.   |
// |                                        |                                                      | TheCommandLineRefusesAbsurdSizesAndHonoursMaxTets     |
// | unwritable output path                 | "cannot write /nonexistent-dir/out.msh"              | CliTest.UnwritableOutputFailsWithStatusOne,           |
// | (checked before any meshing)           | "cannot write DIR: it is a directory"                | UnwritablePathsFailBeforeMeshing; MeshIo.FailedWrite- |
// |                                        |                                                      | LeavesNoFile                                          |
// | write failing midway (several outputs) | "cannot write PATH: File too large"                  | CliTest.AFailedWriteRemovesTheFilesTheRunWrote        |
// | full disk (no partial file left)       | "cannot write PATH: File too large"                  | BadInput.AFullDiskLeavesNoPartialFile                 |

#include <meccano/error.hpp>
#include <meccano/io/mesh_writers.hpp>
#include <meccano/io/surface_readers.hpp>
#include <meccano/mesh/cube_meccano.hpp>
#include <meccano/stages/pipeline.hpp>

#include <scratch_directory.hpp>
#include <test_surfaces.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

namespace meccano {
namespace {

namespace fs = std::filesystem;

class BadInput : public testing::ScratchDirectoryTest {
 protected:
  BadInput() : ScratchDirectoryTest("meccano-bad-input") {
    patch_ = testing::paper_like_patch(6);
    patch_.name = "patch";
  }

  // The message of the InputError that insert_surfaces throws, or "" if it does not throw one.
  std::string insertion_error(const InsertionOptions& options) const {
    try {
      insert_surfaces(make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0), {&patch_, 1}, options);
    } catch (const InputError& error) {
      return error.what();
    }
    return {};
  }

  // Runs a shell command line; returns its exit status, its output (stdout and stderr) in `output`.
  int shell(const std::string& command, std::string& output) const {
    const fs::path log = dir_ / "output.log";
    const int raw = std::system((command + " > " + log.string() + " 2>&1").c_str());
    std::ifstream in(log);
    output.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    fs::remove(log);
    return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  }

  TriangleSurface patch_;
};

TEST_F(BadInput, NonPositiveResolutionIsRefusedByTheLibrary) {
  for (const double resolution : {0.0, -0.1, std::numeric_limits<double>::quiet_NaN()}) {
    InsertionOptions options;
    options.resolution = resolution;
    EXPECT_NE(insertion_error(options).find("the resolution l_r must be positive"), std::string::npos) << resolution;
  }
}

TEST_F(BadInput, ATinyResolutionIsRefusedBeforeRefining) {
  InsertionOptions options;
  options.resolution = 1e-5;  // about 10^12 tets: it would never fit
  const std::string message = insertion_error(options);
  EXPECT_NE(message.find("the resolution l_r = 1e-05 would make about"), std::string::npos) << message;
  EXPECT_NE(message.find("GiB of memory), above the limit of " + std::to_string(default_max_tets) + " tets"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("--max-tets"), std::string::npos) << message;
}

TEST_F(BadInput, TheLimitIsOverridable) {
  InsertionOptions options;
  options.resolution = 0.1;
  options.last_stage = Stage::volumetric;
  const TetMesh meccano = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0);
  const std::int64_t estimate = estimate_tets(meccano.meccano, meccano.num_tets(), {&patch_, 1}, options.resolution);
  options.max_tets = estimate - 1;
  EXPECT_NE(insertion_error(options).find("above the limit of " + std::to_string(estimate - 1)), std::string::npos);
  options.max_tets = estimate;
  const InsertionResult result = insert_surfaces(make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 0), {&patch_, 1}, options);
  EXPECT_GT(result.mesh.num_tets(), 6);
}

// The estimate is within 30 % of the count after healing (SUS adds no tets), on the cube example at
// resolutions of the three level types, in the unit cube and in a box of unequal cells.
TEST_F(BadInput, TheEstimateIsWithinThirtyPercentOfTheCount) {
  const TriangleSurface cube_example =
      read_surface((fs::path(MECCANO_TEST_DATA_DIR).parent_path().parent_path() / "meshes/cube_example.obj").string());
  for (const Box& box : {Box{{0, 0, 0}, {1, 1, 1}}, Box{{-0.1, 0, 0.05}, {1.3, 1.05, 0.95}}})
    for (const double resolution : {0.06, 0.05, 0.04}) {
      SCOPED_TRACE("box " + std::to_string(box.max.x()) + ", l_r " + std::to_string(resolution));
      InsertionOptions options;
      options.resolution = resolution;
      options.last_stage = Stage::approximation;
      const TetMesh meccano = make_cube_meccano(box, 0);
      const InsertionResult result = insert_surfaces(meccano, {&cube_example, 1}, options);
      const double estimate =
          static_cast<double>(estimate_tets(meccano.meccano, meccano.num_tets(), {&cube_example, 1}, resolution));
      EXPECT_EQ(result.estimated_tets, static_cast<std::int64_t>(estimate));
      EXPECT_NEAR(estimate / result.mesh.num_tets(), 1.0, 0.3) << estimate << " for " << result.mesh.num_tets();
    }
}

TEST_F(BadInput, TheCommandLineRefusesAbsurdSizesAndHonoursMaxTets) {
  std::ofstream(dir_ / "patch.obj") << [&] {
    std::string obj;
    for (const auto& p : patch_.points)
      obj += "v " + std::to_string(p.x()) + " " + std::to_string(p.y()) + " " + std::to_string(p.z()) + "\n";
    for (const auto& t : patch_.triangles)
      obj += "f " + std::to_string(t[0] + 1) + " " + std::to_string(t[1] + 1) + " " + std::to_string(t[2] + 1) + "\n";
    return obj;
  }();
  const std::string cli = std::string(MECCANO_CLI) + " --box 0,0,0,1,1,1 --quiet ";
  const std::string out = (dir_ / "out.msh").string();
  std::string output;
  EXPECT_EQ(shell(cli + "--surface " + (dir_ / "patch.obj").string() + " --resolution 1e-6 --output " + out, output),
            1);
  EXPECT_NE(output.find("the resolution l_r = 1e-06 would make about"), std::string::npos) << output;
  EXPECT_EQ(shell(cli + "--level 40 --output " + out, output), 1);
  EXPECT_NE(output.find("the meccano mesh (--cells, --level) would make about"), std::string::npos) << output;
  EXPECT_EQ(shell(cli + "--cells 1024,1024,1024 --level 40 --output " + out, output), 1) << "beyond 64 bits";
  EXPECT_NE(output.find("the meccano mesh (--cells, --level) would make about"), std::string::npos) << output;
  EXPECT_EQ(shell(cli + "--level 4 --max-tets 95 --output " + out, output), 1) << "6 x 2^4 = 96 tets";
  EXPECT_NE(output.find("above the limit of 95 tets"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(shell(cli + "--level 4 --max-tets 96 --output " + out, output), 0) << output;
  EXPECT_TRUE(fs::exists(out));
  for (const char* bad : {"0", "-3", "lots"}) {
    EXPECT_EQ(shell(cli + "--max-tets " + bad + " --output " + out, output), 2) << bad;
    EXPECT_NE(output.find("--max-tets"), std::string::npos) << output;
  }
}

// A full disk, simulated with a file size limit (writes past it fail with EFBIG, as they would with
// ENOSPC). /dev/full is not usable here: the writer's temporary lives next to the target, so as root it
// would be created in /dev and renamed over the device.
TEST_F(BadInput, AFullDiskLeavesNoPartialFile) {
  const fs::path out = dir_ / "big.msh";
  std::string output;
  // 16 blocks of 512 bytes; the mesh of level 9 takes about 300 KB. SIGXFSZ ignored: write() fails instead.
  const int status = shell("trap '' XFSZ; ulimit -f 16; exec " + std::string(MECCANO_CLI) +
                               " --box 0,0,0,1,1,1 --level 9 --quiet --output " + out.string(),
                           output);
  EXPECT_EQ(status, 1) << output;
  EXPECT_NE(output.find("cannot write " + out.string() + ": File too large"), std::string::npos) << output;
  EXPECT_TRUE(fs::is_empty(dir_)) << "a partial file or temporary is left";

  // The library's writer, in a child process with the same limit.
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{8192, 8192};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    const TetMesh mesh = make_cube_meccano({{0, 0, 0}, {1, 1, 1}}, 9);
    try {
      write_msh41(mesh, standard_groups(mesh), out.string());
    } catch (const InputError& error) {
      ::_exit(std::string(error.what()).find("cannot write " + out.string()) == 0 ? 0 : 3);
    }
    ::_exit(4);  // no error
  }
  int raw = 0;
  ::waitpid(child, &raw, 0);
  EXPECT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 0) << "child status " << raw;
  EXPECT_TRUE(fs::is_empty(dir_)) << "a partial file or temporary is left";
}

}  // namespace
}  // namespace meccano
