// One pass over the file's bytes with a ByteCursor; node tags are resolved once every section is read
// (a file may list its elements first).
#include "io/msh_parser.hpp"

#include "io/byte_cursor.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <unordered_map>

namespace meccano::readers {
namespace {

// Nodes of the Gmsh element types (MSH_* in Gmsh's GmshDefines.h), to read the elements kept and to
// skip the others in binary data; 0 when unknown.
int nodes_per_element(long long type) {
  constexpr std::array<int, 32> kNodes = {0, 2,  3,  4,  4, 8,  6,  5,  3,  6,  9, 10, 27, 18, 14, 1,
                                          8, 20, 15, 13, 9, 10, 12, 15, 15, 21, 4, 5,  6,  20, 35, 56};
  if (type >= 0 && type < static_cast<long long>(kNodes.size())) return kNodes[static_cast<std::size_t>(type)];
  if (type == 92) return 64;   // MSH_HEX_64, third-order hexahedron
  if (type == 93) return 125;  // MSH_HEX_125, fourth-order hexahedron
  return 0;
}

class MshParser {
 public:
  MshParser(const std::string& path, std::string_view bytes, std::span<const int> kept_types)
      : cursor_(path, bytes), kept_types_(kept_types) {
    file_.physical_sets.emplace_back();  // of the elements in no group
  }

  MshFile parse() {
    read_format();
    while (const std::optional<Token> section = cursor_.next_token()) {
      if (!section->text.starts_with('$'))
        cursor_.fail_at(section->line, "expected a section such as '$Nodes', found " + quoted(section->text));
      const std::string name(section->text.substr(1));
      const std::string end = "$End" + name;
      if (name == "Nodes") {
        version4_ ? read_nodes_v4() : read_nodes_v2();
      } else if (name == "Elements") {
        version4_ ? read_elements_v4() : read_elements_v2();
      } else if (name == "PhysicalNames") {
        read_physical_names();
      } else if (name == "Entities" && version4_) {
        read_entities();
      } else {
        if (!cursor_.skip_past(end))
          cursor_.fail_at(section->line, "section " + quoted(section->text) + " has no '" + end + "'");
        continue;
      }
      expect(end);
    }
    resolve_nodes();
    return std::move(file_);
  }

 private:
  // A section's end marker: text, after its binary data if any.
  void expect(const std::string& keyword) {
    binary_data_ = false;
    const Token token = cursor_.expect_token("'" + keyword + "'");
    if (token.text != keyword) cursor_.fail_at(token.line, "expected '" + keyword + "', found " + quoted(token.text));
  }

  void read_format() {
    const Token start = cursor_.expect_token("'$MeshFormat'");
    if (start.text != "$MeshFormat")
      cursor_.fail_at(start.line, "not a Gmsh MSH file: expected '$MeshFormat', found " + quoted(start.text));
    const Token version = cursor_.expect_token("MSH version");
    version4_ = version.text == "4.1";
    if (!version4_ && version.text != "2.2")
      cursor_.fail_at(version.line, "unsupported MSH version " + quoted(version.text) + " (supported: 2.2, 4.1)");
    const Token type = cursor_.expect_token("file type");
    const long long file_type = cursor_.integer(type, "file type");
    if (file_type != 0 && file_type != 1)
      cursor_.fail_at(type.line, "file type " + quoted(type.text) + " is neither 0 (ASCII) nor 1 (binary)");
    binary_ = file_type == 1;
    const Token size = cursor_.expect_token("data size");
    if (cursor_.integer(size, "data size") != 8 && binary_)
      cursor_.fail_at(size.line, "unsupported data size " + quoted(size.text) + " in a binary file (8 expected)");
    start_binary_data();
    if (binary_) {
      const auto one = cursor_.binary<std::int32_t>("endianness check");
      if (one != 1)
        cursor_.fail("binary endianness check reads " + std::to_string(one) +
                     " instead of 1: the file was written with another byte order");
    }
    expect("$EndMeshFormat");
  }

  // The binary data of a section starts on the line after its header (MSH 2.2: after its count).
  void start_binary_data() {
    if (!binary_) return;
    cursor_.skip_line();
    binary_data_ = true;
  }

  // Fields by their type in binary data: 'int' (4 bytes), 'size_t' (8 bytes), 'double'.
  long long int_field(std::string_view what) {
    if (binary_data_) return cursor_.binary<std::int32_t>(what);
    return cursor_.integer(cursor_.expect_token(what), what);
  }
  std::uint64_t size_field(std::string_view what) {
    if (binary_data_) return cursor_.binary<std::uint64_t>(what);
    const Token token = cursor_.expect_token(what);
    const long long value = cursor_.integer(token, what);
    if (value < 0) cursor_.fail_at(token.line, std::string(what) + " " + std::to_string(value) + " is negative");
    return static_cast<std::uint64_t>(value);
  }
  double real_field(std::string_view what) {
    if (binary_data_) return cursor_.binary<double>(what);
    return cursor_.number(cursor_.expect_token(what), what);
  }
  // Node and element tags: 'int' in MSH 2.2, 'size_t' in MSH 4.1.
  std::uint64_t tag_field(std::string_view what) {
    if (version4_ || !binary_data_) return size_field(what);
    const long long tag = int_field(what);
    if (tag < 0) cursor_.fail(std::string(what) + " " + std::to_string(tag) + " is negative");
    return static_cast<std::uint64_t>(tag);
  }

  void check_block(std::uint64_t in_block, std::uint64_t read, std::uint64_t announced, std::string_view what) {
    if (in_block > announced - read)
      cursor_.fail("a block of " + std::to_string(in_block) + " " + std::string(what) + "s exceeds the " +
                   std::to_string(announced) + " announced by the section header");
  }
  void check_total(std::uint64_t read, std::uint64_t announced, const std::string& what) {
    if (read != announced)
      cursor_.fail(what + " blocks hold " + std::to_string(read) + " " + what + "s, the section header announces " +
                   std::to_string(announced));
  }

  void read_physical_names() {
    const std::uint64_t count = size_field("number of physical names");
    cursor_.check_count(count, 6, "physical name");
    for (std::uint64_t i = 0; i < count; ++i) {
      const auto dimension = static_cast<int>(int_field("physical dimension"));
      const Token tag = cursor_.expect_token("physical tag");
      const auto value = static_cast<int>(cursor_.integer(tag, "physical tag"));
      const std::string_view rest = cursor_.rest_of_line();  // "name", names may hold blanks
      const std::size_t open = rest.find('"');
      const std::size_t close = open == std::string_view::npos ? open : rest.find('"', open + 1);
      if (close == std::string_view::npos)
        cursor_.fail_at(tag.line, "physical name of group " + std::to_string(value) + " is not a quoted string");
      file_.physical_names[{dimension, value}] = std::string(rest.substr(open + 1, close - open - 1));
    }
  }

  // MSH 4.1: the physical tags of every entity, which its elements belong to.
  void read_entities() {
    start_binary_data();
    std::array<std::uint64_t, 4> counts{};
    for (std::uint64_t& count : counts) count = size_field("number of entities");
    std::vector<int> physical;
    for (int dimension = 0; dimension < 4; ++dimension) {
      cursor_.check_count(counts[dimension], binary_ ? 4 + 3 * 8 + 8 : 6, "entity");
      for (std::uint64_t i = 0; i < counts[dimension]; ++i) {
        const auto tag = static_cast<int>(int_field("entity tag"));
        for (int k = 0; k < (dimension == 0 ? 3 : 6); ++k) real_field("entity bounding box");
        const std::uint64_t physical_count = size_field("number of physical tags");
        cursor_.check_count(physical_count, binary_ ? 4 : 2, "physical tag");
        physical.clear();
        for (std::uint64_t k = 0; k < physical_count; ++k)
          physical.push_back(static_cast<int>(int_field("physical tag")));
        entity_set_[{dimension, tag}] = add_physical_set(physical);
        if (dimension == 0) continue;
        const std::uint64_t bounding = size_field("number of bounding entities");
        cursor_.check_count(bounding, binary_ ? 4 : 2, "bounding entity");
        for (std::uint64_t k = 0; k < bounding; ++k) int_field("bounding entity tag");
      }
    }
  }
  int add_physical_set(const std::vector<int>& physical) {
    if (physical.empty()) return 0;
    file_.physical_sets.push_back(physical);
    return static_cast<int>(file_.physical_sets.size()) - 1;
  }

  Eigen::Vector3d point(std::uint64_t tag) {
    const std::string defect = "node " + std::to_string(tag) + " has a non-finite coordinate";
    Eigen::Vector3d p;
    for (int axis = 0; axis < 3; ++axis) {
      if (binary_data_) {
        p[axis] = cursor_.binary<double>("node coordinate");
        if (!std::isfinite(p[axis])) cursor_.fail(defect);
        continue;
      }
      const Token token = cursor_.expect_token("node coordinate");
      p[axis] = cursor_.number(token, "node coordinate");
      if (!std::isfinite(p[axis])) cursor_.fail_at(token.line, defect + " " + quoted(token.text));
    }
    return p;
  }
  void add_node(std::uint64_t tag, const Eigen::Vector3d& p) {
    if (!node_index_.emplace(tag, static_cast<int>(file_.points.size())).second)
      cursor_.fail("node tag " + std::to_string(tag) + " is defined twice");
    file_.points.push_back(p);
    file_.point_tags.push_back(tag);
  }
  void reserve_nodes(std::uint64_t count) {
    file_.points.reserve(file_.points.size() + count);
    file_.point_tags.reserve(file_.point_tags.size() + count);
    node_index_.reserve(node_index_.size() + count);
  }

  void read_nodes_v2() {
    const std::uint64_t count = size_field("number of nodes");
    start_binary_data();
    cursor_.check_count(count, binary_ ? 4 + 3 * 8 : 8, "node");
    reserve_nodes(count);
    for (std::uint64_t i = 0; i < count; ++i) {
      const std::uint64_t tag = tag_field("node tag");
      add_node(tag, point(tag));
    }
  }

  // The header of a MSH 4.1 $Nodes or $Elements section: numbers of blocks and of items (the tag range
  // is not needed). `item_bytes` is the least an item takes in binary data.
  std::pair<std::uint64_t, std::uint64_t> v4_section_header(const std::string& item, std::uint64_t item_bytes) {
    start_binary_data();
    const std::uint64_t blocks = size_field("number of " + item + " blocks");
    const std::uint64_t count = size_field("number of " + item + "s");
    size_field("minimum " + item + " tag");
    size_field("maximum " + item + " tag");
    cursor_.check_count(blocks, binary_ ? 20 : 8, item + " block");
    cursor_.check_count(count, binary_ ? item_bytes : 4, item);
    return {blocks, count};
  }

  void read_nodes_v4() {
    const auto [blocks, count] = v4_section_header("node", 8 + 3 * 8);
    reserve_nodes(count);
    std::vector<std::uint64_t> tags;
    std::uint64_t read = 0;
    for (std::uint64_t b = 0; b < blocks; ++b) {
      const long long dimension = int_field("entity dimension");
      int_field("entity tag");
      const long long parametric = int_field("parametric flag");
      const std::uint64_t in_block = size_field("number of nodes in block");
      if (dimension < 0 || dimension > 3)
        cursor_.fail("entity dimension " + std::to_string(dimension) + " is not 0..3");
      if (parametric != 0 && parametric != 1)
        cursor_.fail("parametric flag " + std::to_string(parametric) + " is not 0 or 1");
      check_block(in_block, read, count, "node");
      tags.clear();  // all the tags of a block precede its coordinates
      for (std::uint64_t i = 0; i < in_block; ++i) tags.push_back(tag_field("node tag"));
      for (const std::uint64_t tag : tags) {
        const Eigen::Vector3d p = point(tag);
        // Parametric nodes add u (curve), u v (surface) or u v w (volume) after x y z.
        for (long long k = 0; k < (parametric == 1 ? dimension : 0); ++k) real_field("parametric coordinate");
        add_node(tag, p);
      }
      read += in_block;
    }
    check_total(read, count, "node");
  }

  bool kept(long long type) const { return std::ranges::find(kept_types_, type) != kept_types_.end(); }

  // The nodes of an element of a kept type; the node tags are resolved at the end.
  void read_element(long long type, std::uint64_t tag, int physical) {
    MshElements& elements = file_.elements[static_cast<int>(type)];
    elements.tags.push_back(tag);
    elements.physical.push_back(physical);
    std::vector<std::uint64_t>& nodes = node_tags_[static_cast<int>(type)];
    for (int k = 0; k < nodes_per_element(type); ++k) nodes.push_back(tag_field("node tag"));
  }
  // Skips `count` binary elements of `type`, each made of `fields_besides_nodes` plus its node tags.
  void skip_binary_elements(long long type, std::uint64_t count, std::uint64_t fields_besides_nodes,
                            std::uint64_t field_bytes) {
    const int nodes = nodes_per_element(type);
    if (nodes == 0)
      cursor_.fail("unsupported element type " + std::to_string(type) +
                   " in a binary file (its node count is unknown)");
    const std::uint64_t element_bytes = (fields_besides_nodes + static_cast<std::uint64_t>(nodes)) * field_bytes;
    cursor_.check_count(count, element_bytes, "element");
    cursor_.skip_bytes(count * element_bytes, "elements");
  }
  // MSH 2.2: an element's tags, the first its physical group (0: none).
  int v2_physical(long long tags) {
    int set = 0;
    for (long long k = 0; k < tags; ++k) {
      const long long value = int_field("element tag");
      if (k > 0 || value == 0) continue;
      const auto [found, added] = v2_set_.try_emplace(static_cast<int>(value), 0);
      if (added) found->second = add_physical_set({static_cast<int>(value)});
      set = found->second;
    }
    return set;
  }

  void read_elements_v2() {
    const std::uint64_t count = size_field("number of elements");
    start_binary_data();
    cursor_.check_count(count, binary_ ? 12 : 4, "element");
    if (!binary_) {  // one element per line: tag, type, number of tags, tags, nodes
      for (std::uint64_t i = 0; i < count; ++i) {
        const std::uint64_t tag = tag_field("element tag");
        const long long type = int_field("element type");
        if (kept(type)) {
          const Token tags = cursor_.expect_token("number of tags");
          const long long number = cursor_.integer(tags, "number of tags");
          if (number < 0)
            cursor_.fail_at(tags.line, "element " + std::to_string(tag) + " has " + std::to_string(number) + " tags");
          read_element(type, tag, v2_physical(number));
        }
        cursor_.skip_line();
      }
      return;
    }
    // Binary elements come in blocks sharing a header: type, number of elements, number of tags.
    for (std::uint64_t read = 0; read < count;) {
      const long long type = int_field("element type");
      const long long in_block = int_field("number of elements in block");
      const long long tags = int_field("number of tags");
      if (in_block < 1 || tags < 0) cursor_.fail("malformed element block header");
      const auto elements = static_cast<std::uint64_t>(in_block);
      check_block(elements, read, count, "element");
      if (kept(type)) {
        for (std::uint64_t i = 0; i < elements; ++i) {
          const std::uint64_t tag = tag_field("element tag");
          read_element(type, tag, v2_physical(tags));
        }
      } else {
        skip_binary_elements(type, elements, 1 + static_cast<std::uint64_t>(tags), 4);
      }
      read += elements;
    }
  }

  void read_elements_v4() {
    const auto [blocks, count] = v4_section_header("element", 16);
    std::uint64_t read = 0;
    for (std::uint64_t b = 0; b < blocks; ++b) {
      const auto dimension = static_cast<int>(int_field("entity dimension"));
      const auto entity = static_cast<int>(int_field("entity tag"));
      const long long type = int_field("element type");
      const std::uint64_t in_block = size_field("number of elements in block");
      check_block(in_block, read, count, "element");
      if (!kept(type) && binary_) {
        skip_binary_elements(type, in_block, 1, 8);
      } else {
        const auto set = entity_set_.find({dimension, entity});
        const int physical = set == entity_set_.end() ? 0 : set->second;
        for (std::uint64_t i = 0; i < in_block; ++i) {
          const std::uint64_t tag = tag_field("element tag");
          if (kept(type)) read_element(type, tag, physical);
          if (!binary_) cursor_.skip_line();  // one element per line: tag, nodes
        }
      }
      read += in_block;
    }
    check_total(read, count, "element");
  }

  void resolve_nodes() {
    for (auto& [type, nodes] : node_tags_) {
      MshElements& elements = file_.elements[type];
      const auto per_element = static_cast<std::size_t>(nodes_per_element(type));
      elements.vertices.reserve(nodes.size());
      for (std::size_t k = 0; k < nodes.size(); ++k) {
        const auto found = node_index_.find(nodes[k]);
        if (found == node_index_.end())
          throw InputError(cursor_.path() + ": element " + std::to_string(elements.tags[k / per_element]) + ": node " +
                           std::to_string(nodes[k]) + " is not defined in $Nodes");
        elements.vertices.push_back(found->second);
      }
    }
  }

  ByteCursor cursor_;
  std::span<const int> kept_types_;
  bool binary_ = false;
  bool binary_data_ = false;  // inside a section's binary data (MSH 2.2 section counts are text)
  bool version4_ = false;
  MshFile file_;
  std::unordered_map<std::uint64_t, int> node_index_;
  std::map<int, std::vector<std::uint64_t>> node_tags_;  // of the kept elements, by type
  std::map<std::pair<int, int>, int> entity_set_;        // MSH 4.1: (dimension, entity tag) -> physical set
  std::map<int, int> v2_set_;                            // MSH 2.2: physical tag -> its physical set
};

}  // namespace

MshFile parse_msh_file(const std::string& path, std::string_view bytes, std::span<const int> kept_types) {
  return MshParser(path, bytes, kept_types).parse();
}

}  // namespace meccano::readers
