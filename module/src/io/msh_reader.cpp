// The MSH volume-mesh reader (io/msh_reader.hpp). One pass over the file's bytes: text fields are
// whitespace-separated tokens (with line numbers), binary fields are copied from the bytes; every read
// is bounds-checked. Node tags are resolved once the whole file is read, groups built at the end.
#include <meccano/io/msh_reader.hpp>

#include <meccano/error.hpp>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string_view>
#include <unordered_map>

namespace meccano {
namespace {

constexpr int kTriangle = 2;  // Gmsh element types
constexpr int kTet = 4;

// Nodes per Gmsh element type, to skip the elements not read; 0 when unknown.
int nodes_of_type(long long type) {
  constexpr std::array<int, 32> kNodes = {0, 2,  3,  4,  4,  8, 6,  5,  3,  6,  9,  10, 27, 18, 14, 1,
                                          8, 20, 15, 13, 9, 10, 12, 15, 15, 21, 4,  5,  6,  20, 35, 56};
  return type >= 0 && type < static_cast<long long>(kNodes.size()) ? kNodes[static_cast<std::size_t>(type)] : 0;
}

// A record of an element as read: its type, the file's tags, and its physical groups.
struct Record {
  int type;
  std::uint64_t tag;
  std::array<std::uint64_t, 4> nodes;
  std::vector<int> physical;  // physical tags of the element's dimension
};

class MshParser {
 public:
  MshParser(std::string path, std::string_view bytes) : path_(std::move(path)), bytes_(bytes) {}

  MshMesh parse() {
    read_format();
    while (const auto section = token()) {
      if (!section->starts_with('$')) fail("expected a section such as '$Nodes', found " + shown(*section));
      const std::string name(section->substr(1));
      if (name == "Nodes") {
        version4_ ? read_nodes_v4() : read_nodes_v2();
      } else if (name == "Elements") {
        version4_ ? read_elements_v4() : read_elements_v2();
      } else if (name == "PhysicalNames") {
        read_physical_names();
      } else if (name == "Entities" && version4_) {
        read_entities();
      } else {
        const std::size_t end = bytes_.find("$End" + name, pos_);
        if (end == std::string_view::npos) fail("section " + shown(*section) + " has no '$End" + name + "'");
        advance_to(end);
      }
      expect("$End" + name);
    }
    return finish();
  }

 private:
  [[noreturn]] void fail(const std::string& defect) const {
    // Binary data holds newlines by chance: lines are counted in text files only.
    const std::string where = binary_ ? "byte " + std::to_string(pos_) : "line " + std::to_string(line_);
    throw InputError(path_ + ": " + where + ": " + defect);
  }
  static std::string shown(std::string_view text) {
    std::string out;
    for (const char c : text.substr(0, 40)) out += static_cast<unsigned char>(c) < 0x20 ? '?' : c;
    return "'" + out + (text.size() > 40 ? "...'" : "'");
  }

  void advance_to(std::size_t end) {
    line_ += static_cast<int>(std::count(bytes_.begin() + static_cast<std::ptrdiff_t>(pos_),
                                         bytes_.begin() + static_cast<std::ptrdiff_t>(end), '\n'));
    pos_ = end;
  }
  std::optional<std::string_view> token() {
    while (pos_ < bytes_.size() && std::isspace(static_cast<unsigned char>(bytes_[pos_])))
      line_ += bytes_[pos_++] == '\n';
    if (pos_ == bytes_.size()) return std::nullopt;
    const std::size_t start = pos_;
    while (pos_ < bytes_.size() && !std::isspace(static_cast<unsigned char>(bytes_[pos_]))) ++pos_;
    return bytes_.substr(start, pos_ - start);
  }
  std::string_view expect_token(std::string_view what) {
    if (const auto t = token()) return *t;
    fail("unexpected end of file: expected " + std::string(what));
  }
  void expect(const std::string& keyword) {
    binary_data_ = false;
    const std::string_view t = expect_token("'" + keyword + "'");
    if (t != keyword) fail("expected '" + keyword + "', found " + shown(t));
  }
  void skip_line() {
    const std::size_t end = bytes_.find('\n', pos_);
    advance_to(end == std::string_view::npos ? bytes_.size() : end + 1);
  }
  template <class T>
  T text_number(std::string_view what) {
    const std::string_view t = expect_token(what);
    T value{};
    const auto [end, error] = std::from_chars(t.data(), t.data() + t.size(), value);
    if (error != std::errc{} || end != t.data() + t.size()) fail("malformed " + std::string(what) + " " + shown(t));
    return value;
  }
  template <class T>
  T binary_value(std::string_view what) {
    if (bytes_.size() - pos_ < sizeof(T)) fail("unexpected end of file: truncated binary data (" + std::string(what) + ")");
    T value;
    std::memcpy(&value, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }
  // Binary data of a section starts on the line after its header.
  void start_binary_data() {
    if (!binary_) return;
    skip_line();
    binary_data_ = true;
  }

  // Fields by their binary type: 'int' (4 bytes), 'size_t' (8 bytes), 'double'.
  long long int_field(std::string_view what) {
    return binary_data_ ? binary_value<std::int32_t>(what) : text_number<long long>(what);
  }
  std::uint64_t size_field(std::string_view what) {
    if (binary_data_) return binary_value<std::uint64_t>(what);
    const long long value = text_number<long long>(what);
    if (value < 0) fail(std::string(what) + " " + std::to_string(value) + " is negative");
    return static_cast<std::uint64_t>(value);
  }
  double double_field(std::string_view what) {
    return binary_data_ ? binary_value<double>(what) : text_number<double>(what);
  }
  // Node and element tags: 'int' in MSH 2.2, 'size_t' in MSH 4.1.
  std::uint64_t tag_field(std::string_view what) {
    if (version4_) return size_field(what);
    const long long tag = int_field(what);
    if (tag < 0) fail(std::string(what) + " " + std::to_string(tag) + " is negative");
    return static_cast<std::uint64_t>(tag);
  }
  // A count read from the file must fit in the bytes left, each item taking at least `bytes`: a corrupt
  // count is an error, not a huge allocation.
  void check_count(std::uint64_t count, std::uint64_t bytes, std::string_view what) {
    if (count > (bytes_.size() - pos_) / bytes)
      fail("the file announces " + std::to_string(count) + " " + std::string(what) + "s, more than its remaining " +
           std::to_string(bytes_.size() - pos_) + " bytes can hold");
  }

  void read_format() {
    expect("$MeshFormat");
    const std::string_view version = expect_token("MSH version");
    version4_ = version == "4.1";
    if (!version4_ && version != "2.2") fail("unsupported MSH version " + shown(version) + " (supported: 2.2, 4.1)");
    const long long type = text_number<long long>("file type");
    if (type != 0 && type != 1) fail("file type " + std::to_string(type) + " is neither 0 (ASCII) nor 1 (binary)");
    binary_ = type == 1;
    const long long size = text_number<long long>("data size");
    if (binary_ && size != 8) fail("unsupported data size " + std::to_string(size) + " in a binary file (8 expected)");
    start_binary_data();
    if (binary_ && binary_value<std::int32_t>("endianness check") != 1)
      fail("the binary endianness check does not read 1: the file was written with another byte order");
    expect("$EndMeshFormat");
  }

  void read_physical_names() {
    const long long count = text_number<long long>("number of physical names");
    if (count < 0) fail("negative number of physical names");
    check_count(static_cast<std::uint64_t>(count), 6, "physical name");
    for (long long i = 0; i < count; ++i) {
      const int dimension = text_number<int>("physical dimension");
      const int tag = text_number<int>("physical tag");
      const std::size_t open = bytes_.find('"', pos_), close = bytes_.find('"', open + 1);
      const std::size_t eol = bytes_.find('\n', pos_);
      if (open == std::string_view::npos || close == std::string_view::npos || close > eol)
        fail("physical name of group " + std::to_string(tag) + " is not a quoted string");
      names_[{dimension, tag}] = std::string(bytes_.substr(open + 1, close - open - 1));
      pos_ = close + 1;
    }
  }

  // MSH 4.1: the physical tags of every entity, which its elements belong to.
  void read_entities() {
    start_binary_data();
    std::array<std::uint64_t, 4> counts{};
    for (auto& c : counts) c = size_field("number of entities");
    for (int dimension = 0; dimension < 4; ++dimension) {
      check_count(counts[dimension], binary_ ? 4 + 3 * 8 + 8 : 6, "entity");
      for (std::uint64_t i = 0; i < counts[dimension]; ++i) {
        const int tag = static_cast<int>(int_field("entity tag"));
        for (int k = 0; k < (dimension == 0 ? 3 : 6); ++k) double_field("entity bounding box");
        const std::uint64_t physical_count = size_field("number of physical tags");
        check_count(physical_count, binary_ ? 4 : 2, "physical tag");
        std::vector<int>& physical = entity_groups_[{dimension, tag}];
        for (std::uint64_t k = 0; k < physical_count; ++k) physical.push_back(static_cast<int>(int_field("physical tag")));
        if (dimension == 0) continue;
        const std::uint64_t bounding = size_field("number of bounding entities");
        check_count(bounding, binary_ ? 4 : 2, "bounding entity");
        for (std::uint64_t k = 0; k < bounding; ++k) int_field("bounding entity tag");
      }
    }
  }

  Eigen::Vector3d point(std::uint64_t tag) {
    Eigen::Vector3d p;
    for (int axis = 0; axis < 3; ++axis) p[axis] = double_field("node coordinate");
    if (!p.allFinite()) fail("node " + std::to_string(tag) + " has a non-finite coordinate");
    return p;
  }
  void add_node(std::uint64_t tag, const Eigen::Vector3d& p) {
    if (!node_index_.emplace(tag, static_cast<int>(mesh_.points.size())).second)
      fail("node tag " + std::to_string(tag) + " is defined twice");
    mesh_.points.push_back(p);
    mesh_.point_tags.push_back(tag);
  }

  void read_nodes_v2() {
    const std::uint64_t count = size_field("number of nodes");
    start_binary_data();
    check_count(count, binary_ ? 4 + 3 * 8 : 8, "node");
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
    check_count(blocks, binary_ ? 20 : 8, item + " block");
    check_count(count, binary_ ? item_bytes : 4, item);
    return {blocks, count};
  }

  void read_nodes_v4() {
    const auto [blocks, count] = v4_section_header("node", 32);
    std::uint64_t read = 0;
    std::vector<std::uint64_t> tags;
    for (std::uint64_t b = 0; b < blocks; ++b) {
      const long long dimension = int_field("entity dimension");
      int_field("entity tag");
      const long long parametric = int_field("parametric flag");
      const std::uint64_t in_block = size_field("number of nodes in block");
      if (dimension < 0 || dimension > 3) fail("entity dimension " + std::to_string(dimension) + " is not 0..3");
      if (in_block > count - read)
        fail("node blocks hold more nodes than the " + std::to_string(count) + " the section header announces");
      tags.clear();  // a block's tags precede its coordinates
      for (std::uint64_t i = 0; i < in_block; ++i) tags.push_back(tag_field("node tag"));
      for (const std::uint64_t tag : tags) {
        add_node(tag, point(tag));
        for (long long k = 0; k < (parametric ? dimension : 0); ++k) double_field("parametric coordinate");
      }
      read += in_block;
    }
    if (read != count)
      fail("node blocks hold " + std::to_string(read) + " nodes, the section header announces " + std::to_string(count));
  }

  // Reads the nodes of an element of `type` into a record, or skips them for the types not kept.
  void element_nodes(int type, std::uint64_t tag, const std::vector<int>& physical) {
    const int nodes = nodes_of_type(type);
    if (nodes == 0) fail("unsupported element type " + std::to_string(type));
    if (type != kTet && type != kTriangle) {
      for (int k = 0; k < nodes; ++k) tag_field("node tag");
      return;
    }
    Record& record = records_.emplace_back(Record{type, tag, {}, physical});
    for (int k = 0; k < nodes; ++k) record.nodes[k] = tag_field("node tag");
  }

  void read_elements_v2() {
    const std::uint64_t count = size_field("number of elements");
    start_binary_data();
    check_count(count, 8, "element");  // at least a tag and one node
    std::vector<int> physical;
    if (!binary_) {
      for (std::uint64_t i = 0; i < count; ++i) {
        const std::uint64_t tag = tag_field("element tag");
        const int type = static_cast<int>(int_field("element type"));
        const long long tags = int_field("number of tags");
        if (tags < 0 || tags > 64) fail("element " + std::to_string(tag) + " has " + std::to_string(tags) + " tags");
        physical.clear();
        for (long long k = 0; k < tags; ++k) {
          const long long value = int_field("element tag");
          if (k == 0 && value != 0) physical.push_back(static_cast<int>(value));
        }
        element_nodes(type, tag, physical);
      }
      return;
    }
    // Binary elements come in blocks sharing a header: type, number of elements, number of tags.
    for (std::uint64_t read = 0; read < count;) {
      const int type = static_cast<int>(int_field("element type"));
      const long long in_block = int_field("number of elements in block");
      const long long tags = int_field("number of tags");
      if (in_block < 1 || static_cast<std::uint64_t>(in_block) > count - read || tags < 0 || tags > 64)
        fail("malformed element block header");
      for (long long i = 0; i < in_block; ++i) {
        const std::uint64_t tag = tag_field("element tag");
        physical.clear();
        for (long long k = 0; k < tags; ++k) {
          const long long value = int_field("element tag");
          if (k == 0 && value != 0) physical.push_back(static_cast<int>(value));
        }
        element_nodes(type, tag, physical);
      }
      read += static_cast<std::uint64_t>(in_block);
    }
  }

  void read_elements_v4() {
    const auto [blocks, count] = v4_section_header("element", 16);
    std::uint64_t read = 0;
    const std::vector<int> none;
    for (std::uint64_t b = 0; b < blocks; ++b) {
      const int dimension = static_cast<int>(int_field("entity dimension"));
      const int entity = static_cast<int>(int_field("entity tag"));
      const int type = static_cast<int>(int_field("element type"));
      const std::uint64_t in_block = size_field("number of elements in block");
      if (in_block > count - read)
        fail("element blocks hold more elements than the " + std::to_string(count) + " the section header announces");
      const auto groups = entity_groups_.find({dimension, entity});
      const std::vector<int>& physical = groups == entity_groups_.end() ? none : groups->second;
      for (std::uint64_t i = 0; i < in_block; ++i) element_nodes(type, tag_field("element tag"), physical);
      read += in_block;
    }
    if (read != count)
      fail("element blocks hold " + std::to_string(read) + " elements, the section header announces " +
           std::to_string(count));
  }

  // Resolves node tags, merges the records of an element written once per group, builds the groups.
  MshMesh finish() {
    binary_data_ = false;
    // (dimension, sorted vertices) -> element index and the groups it is in so far.
    std::map<std::pair<int, std::array<int, 4>>, std::pair<int, std::vector<int>>> elements;
    std::map<std::pair<int, int>, std::vector<int>> members;  // (dimension, physical tag) -> elements
    for (const Record& r : records_) {
      const int count = r.type == kTet ? 4 : 3;
      std::array<int, 4> vertices{-1, -1, -1, -1};
      for (int k = 0; k < count; ++k) {
        const auto found = node_index_.find(r.nodes[k]);
        if (found == node_index_.end())
          throw InputError(path_ + ": element " + std::to_string(r.tag) + ": node " + std::to_string(r.nodes[k]) +
                           " is not defined in $Nodes");
        vertices[k] = found->second;
      }
      const int dimension = r.type == kTet ? 3 : 2;
      std::array<int, 4> key = vertices;  // a triangle's unused fourth vertex, -1, sorts first
      std::ranges::sort(key);
      auto [slot, added] = elements.try_emplace({dimension, key});
      auto& [index, groups] = slot->second;
      const auto& known_groups = groups;  // clang 14 cannot capture a structured binding
      const bool merged = !added && !r.physical.empty() && std::ranges::none_of(r.physical, [&known_groups](int g) {
                            return std::ranges::count(known_groups, g) > 0;
                          });
      if (!merged) {
        if (dimension == 3) {
          index = static_cast<int>(mesh_.tets.size());
          mesh_.tets.push_back(vertices);
          mesh_.tet_tags.push_back(r.tag);
        } else {
          index = static_cast<int>(mesh_.triangles.size());
          mesh_.triangles.push_back({vertices[0], vertices[1], vertices[2]});
          mesh_.triangle_tags.push_back(r.tag);
        }
        groups.clear();
      }
      for (const int g : r.physical) {
        groups.push_back(g);
        members[{dimension, g}].push_back(index);
      }
    }
    if (mesh_.tets.empty()) throw InputError(path_ + ": no tets (element type 4) in the file");
    for (auto& [key, list] : members) {
      std::sort(list.begin(), list.end());
      list.erase(std::unique(list.begin(), list.end()), list.end());
      const auto name = names_.find(key);
      mesh_.groups.push_back({key.first, key.second, name == names_.end() ? "" : name->second, std::move(list)});
    }
    mesh_.source = path_;
    return std::move(mesh_);
  }

  std::string path_;
  std::string_view bytes_;
  std::size_t pos_ = 0;
  int line_ = 1;
  bool binary_ = false;
  bool binary_data_ = false;  // inside a section's binary data (MSH 2.2 section counts are text)
  bool version4_ = false;
  std::map<std::pair<int, int>, std::string> names_;
  std::map<std::pair<int, int>, std::vector<int>> entity_groups_;
  std::unordered_map<std::uint64_t, int> node_index_;
  std::vector<Record> records_;
  MshMesh mesh_;
};

}  // namespace

MshMesh read_msh_mesh(const std::string& path) {
  std::error_code ignored;
  if (std::filesystem::is_directory(path, ignored)) throw InputError(path + ": cannot open file (it is a directory)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open file");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.empty()) throw InputError(path + ": empty file");
  return MshParser(path, bytes).parse();
}

}  // namespace meccano
