// A small reader of VTK XML UnstructuredGrid files, written for the tests independently of the module's
// writer: a scan of the XML for the Piece and its DataArray elements, ascii or base64 binary (a UInt64
// byte count, then the data, little-endian, uncompressed), with the types UInt8, Int32, Int64, Float64.
// Throws std::runtime_error naming the defect on anything else.
#pragma once

#include <cctype>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace meccano::testing {

struct VtuFile {
  std::int64_t points = 0, cells = 0;                 // the Piece's NumberOfPoints, NumberOfCells
  std::map<std::string, std::vector<double>> field;   // FieldData arrays by name
  std::map<std::string, std::vector<double>> arrays;  // Points ("Points"), Cells and CellData arrays by name
};

namespace vtu_detail {

inline std::map<std::string, std::string> attributes_of(const std::string& tag) {
  static const std::regex attribute(R"re(([A-Za-z_]+)="([^"]*)")re");
  std::map<std::string, std::string> result;
  for (auto it = std::sregex_iterator(tag.begin(), tag.end(), attribute); it != std::sregex_iterator(); ++it)
    result[(*it)[1]] = (*it)[2];
  return result;
}

inline std::vector<unsigned char> base64_decoded(const std::string& text) {
  std::vector<unsigned char> bytes;
  std::uint32_t bits = 0;
  int count = 0;
  for (const char c : text) {
    int value = -1;
    if (c >= 'A' && c <= 'Z') value = c - 'A';
    else if (c >= 'a' && c <= 'z') value = c - 'a' + 26;
    else if (c >= '0' && c <= '9') value = c - '0' + 52;
    else if (c == '+') value = 62;
    else if (c == '/') value = 63;
    else if (c == '=' || std::isspace(static_cast<unsigned char>(c))) continue;
    else throw std::runtime_error(std::string("vtu: '") + c + "' in base64 data");
    bits = bits << 6 | static_cast<std::uint32_t>(value);
    if (++count % 4 == 0) {
      bytes.push_back(static_cast<unsigned char>(bits >> 16));
      bytes.push_back(static_cast<unsigned char>(bits >> 8));
      bytes.push_back(static_cast<unsigned char>(bits));
      bits = 0;
    }
  }
  if (count % 4 == 2) bytes.push_back(static_cast<unsigned char>(bits >> 4));
  if (count % 4 == 3) {
    bytes.push_back(static_cast<unsigned char>(bits >> 10));
    bytes.push_back(static_cast<unsigned char>(bits >> 2));
  }
  if (count % 4 == 1) throw std::runtime_error("vtu: truncated base64 data");
  return bytes;
}

inline std::uint64_t little_endian(const unsigned char* bytes, std::size_t size) {
  std::uint64_t value = 0;
  for (std::size_t k = size; k-- > 0;) value = value << 8 | bytes[k];
  return value;
}

inline std::vector<double> binary_values(const std::string& type, const std::string& content, const std::string& name) {
  const std::vector<unsigned char> bytes = base64_decoded(content);
  if (bytes.size() < 8) throw std::runtime_error("vtu: array " + name + " has no header");
  const std::uint64_t size = little_endian(bytes.data(), 8);
  if (size != bytes.size() - 8)
    throw std::runtime_error("vtu: array " + name + ": header says " + std::to_string(size) + " bytes, data has " +
                             std::to_string(bytes.size() - 8));
  const std::size_t width = type == "UInt8" ? 1 : type == "Int32" ? 4 : type == "Int64" || type == "Float64" ? 8 : 0;
  if (width == 0) throw std::runtime_error("vtu: array " + name + " has type " + type);
  if (size % width != 0) throw std::runtime_error("vtu: array " + name + " has a partial value");
  std::vector<double> values;
  for (std::size_t at = 8; at < bytes.size(); at += width) {
    const std::uint64_t raw = little_endian(bytes.data() + at, width);
    if (type == "Float64") {
      double value;
      std::memcpy(&value, &raw, 8);
      values.push_back(value);
    } else if (type == "Int32") {
      values.push_back(static_cast<std::int32_t>(static_cast<std::uint32_t>(raw)));
    } else if (type == "Int64") {
      values.push_back(static_cast<double>(static_cast<std::int64_t>(raw)));
    } else {
      values.push_back(static_cast<double>(raw));
    }
  }
  return values;
}

}  // namespace vtu_detail

inline VtuFile read_vtu(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("vtu: cannot open " + path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto header = text.find("<VTKFile");
  if (header == std::string::npos) throw std::runtime_error("vtu: no VTKFile element");
  const auto file = vtu_detail::attributes_of(text.substr(header, text.find('>', header) - header));
  if (file.count("type") == 0 || file.at("type") != "UnstructuredGrid" || file.count("byte_order") == 0 ||
      file.at("byte_order") != "LittleEndian" || file.count("header_type") == 0 || file.at("header_type") != "UInt64" ||
      file.count("compressor") != 0)
    throw std::runtime_error("vtu: expected an uncompressed little-endian UnstructuredGrid with UInt64 headers");

  VtuFile result;
  const auto piece = text.find("<Piece");
  if (piece == std::string::npos) throw std::runtime_error("vtu: no Piece");
  const auto piece_attributes = vtu_detail::attributes_of(text.substr(piece, text.find('>', piece) - piece));
  result.points = std::stoll(piece_attributes.at("NumberOfPoints"));
  result.cells = std::stoll(piece_attributes.at("NumberOfCells"));

  const auto field_end = text.find("</FieldData>");
  for (auto start = text.find("<DataArray"); start != std::string::npos; start = text.find("<DataArray", start + 1)) {
    const auto tag_end = text.find('>', start);
    const auto close = text.find("</DataArray>", tag_end);
    if (tag_end == std::string::npos || close == std::string::npos) throw std::runtime_error("vtu: unclosed DataArray");
    const auto attributes = vtu_detail::attributes_of(text.substr(start, tag_end - start));
    const std::string name = attributes.count("Name") ? attributes.at("Name") : "";
    const std::string content = text.substr(tag_end + 1, close - tag_end - 1);
    std::vector<double> values;
    if (attributes.at("format") == "binary") {
      values = vtu_detail::binary_values(attributes.at("type"), content, name);
    } else if (attributes.at("format") == "ascii") {
      std::istringstream numbers(content);
      for (double value; numbers >> value;) values.push_back(value);
    } else {
      throw std::runtime_error("vtu: array " + name + " has format " + attributes.at("format"));
    }
    auto& target = field_end != std::string::npos && start < field_end ? result.field : result.arrays;
    if (!target.emplace(name, std::move(values)).second) throw std::runtime_error("vtu: two arrays named " + name);
  }
  return result;
}

}  // namespace meccano::testing
