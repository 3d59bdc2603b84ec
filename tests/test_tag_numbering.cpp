// One tag numbering in every file of every tool (doc/user_guide.md, "Tags"): the volume `domain` 1; the box
// sides `xmin` ... `zmax` 1-6 and `interface_NAME` 7, 8, ... in the order the surfaces were given. Checked
// by reading back what meccano-immerse writes (MSH 4.1, MSH 2.2, VTU, Medit) and what reference-gmsh and
// reference-tetgen write (MSH 4.1), each group holding elements, and the module's formats agreeing on how
// many.

#include <meccano/io/msh_reader.hpp>
#include <meccano/mesh/tet_mesh.hpp>

#include <run_command.hpp>
#include <scratch_directory.hpp>
#include <test_surfaces.hpp>
#include <vtu_reader.hpp>

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <utility>

namespace meccano {
namespace {

// Per group: its tag, and how many elements it holds. Keys are (dimension, name) and (dimension, tag):
// tags are numbered per dimension.
struct GroupNumbers {
  std::map<std::pair<int, std::string>, int> tag_of;
  std::map<std::pair<int, int>, std::size_t> elements_of;
};

GroupNumbers numbers_in_msh(const std::string& path) {
  GroupNumbers numbers;
  for (const MshGroup& group : read_msh_mesh(path).groups) {
    numbers.tag_of[{group.dimension, group.name}] = group.tag;
    numbers.elements_of[{group.dimension, group.tag}] = group.elements.size();
  }
  return numbers;
}

GroupNumbers numbers_in_vtu(const std::string& path) {
  const testing::VtuFile vtu = testing::read_vtu(path);
  GroupNumbers numbers;
  for (const auto& [name, tag_and_dimension] : vtu.field) {
    EXPECT_EQ(tag_and_dimension.size(), 2u) << name;
    numbers.tag_of[{static_cast<int>(tag_and_dimension.at(1)), name}] = static_cast<int>(tag_and_dimension.at(0));
  }
  const auto& types = vtu.arrays.at("types");
  const auto& group = vtu.arrays.at("group");
  for (std::size_t c = 0; c < types.size(); ++c) {
    EXPECT_TRUE(types[c] == 10 || types[c] == 5) << "cell " << c << " is neither a tet nor a triangle";
    ++numbers.elements_of[{types[c] == 10 ? 3 : 2, static_cast<int>(group.at(c))}];
  }
  return numbers;
}

// Medit: the names are in the comment lines `# Tetrahedra ref 1 domain`; an element's reference is the
// last number of its line.
GroupNumbers numbers_in_medit(const std::string& path) {
  std::ifstream in(path);
  GroupNumbers numbers;
  const std::regex name_line(R"(# (Tetrahedra|Triangles) ref (\d+) (\S+))");
  std::string line;
  int dimension = 0;
  std::size_t left = 0;
  while (std::getline(in, line)) {
    std::smatch match;
    if (std::regex_match(line, match, name_line)) {
      numbers.tag_of[{match[1] == "Tetrahedra" ? 3 : 2, match[3]}] = std::stoi(match[2]);
    } else if (line == "Tetrahedra" || line == "Triangles") {
      dimension = line == "Tetrahedra" ? 3 : 2;
      std::getline(in, line);
      left = std::stoul(line);
    } else if (left > 0) {
      --left;
      ++numbers.elements_of[{dimension, std::stoi(line.substr(line.find_last_of(' ') + 1))}];
    }
  }
  return numbers;
}

class TagNumbering : public testing::ScratchDirectoryTest {
 protected:
  TagNumbering() : ScratchDirectoryTest("meccano-tags") {}

  void SetUp() override {
    ScratchDirectoryTest::SetUp();
    // Given upper first: the numbering follows the input order, not the names.
    const auto pair = testing::stacked_pair(8);
    surfaces_ = " --surface " + testing::write_obj(path("upper.obj"), pair[1]) + ":upper --surface " +
                testing::write_obj(path("lower.obj"), pair[0]) + ":lower";
  }

  // Every file's groups are these, with these tags, each holding elements.
  static void expect_the_numbering(const GroupNumbers& numbers, const std::string& file) {
    std::map<std::pair<int, std::string>, int> expected{{{3, "domain"}, domain_tag},
                                                        {{2, "interface_upper"}, interface_tag(0)},
                                                        {{2, "interface_lower"}, interface_tag(1)}};
    for (int side = 0; side < 6; ++side)
      expected[{2, box_side_name(static_cast<BoxSide>(side))}] = box_side_tag(static_cast<BoxSide>(side));
    EXPECT_EQ(numbers.tag_of, expected) << file;
    for (const auto& [group, tag] : expected)
      EXPECT_GT(numbers.elements_of.count({group.first, tag}) ? numbers.elements_of.at({group.first, tag}) : 0, 0u)
          << file << ": " << group.second << " holds no element";
  }

  std::string surfaces_;
};

TEST_F(TagNumbering, EveryFormatOfTheModuleNumbersTheGroupsAlike) {
  const testing::CommandRun run =
      testing::run_command(std::string(MECCANO_CLI) + " --box 0,0,0,1,1,1 --resolution 0.1 --quiet" + surfaces_ +
                           " --output " + path("a.msh") + " --output " + path("a.vtu") + " --output " + path("a.mesh") +
                           " --msh-version 2.2 --output " + path("a22.msh"));
  ASSERT_EQ(run.status, 0) << run.output;
  const std::map<std::string, GroupNumbers> files{{"a.msh", numbers_in_msh(path("a.msh"))},
                                                  {"a22.msh", numbers_in_msh(path("a22.msh"))},
                                                  {"a.vtu", numbers_in_vtu(path("a.vtu"))},
                                                  {"a.mesh", numbers_in_medit(path("a.mesh"))}};
  for (const auto& [file, numbers] : files) {
    expect_the_numbering(numbers, file);
    EXPECT_EQ(numbers.elements_of, files.at("a.msh").elements_of) << file;
  }
}

TEST_F(TagNumbering, TheReferenceMeshersNumberTheGroupsLikeTheModule) {
  int tools = 0;
  for (const std::string tool : {MECCANO_REFERENCE_GMSH, MECCANO_REFERENCE_TETGEN}) {
    if (tool.empty()) continue;  // not built: its mesher library was not found
    ++tools;
    const std::string output = path("reference.msh");
    const testing::CommandRun run =
        testing::run_command(tool + " --box 0,0,0,1,1,1 --size 0.2 --quiet" + surfaces_ + " --output " + output);
    ASSERT_EQ(run.status, 0) << tool << ": " << run.output;
    expect_the_numbering(numbers_in_msh(output), tool);
  }
  if (tools == 0) GTEST_SKIP() << "neither reference mesher is built";
}

}  // namespace
}  // namespace meccano
