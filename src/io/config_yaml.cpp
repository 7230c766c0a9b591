#include "taiga/io/config_yaml.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <tuple>
#include <vector>

#include "numeric_text.hpp"
#include "taiga/core/angles.hpp"
#include "taiga/core/errors.hpp"

namespace taiga::io {
namespace {

// A quaternion typed by hand with a few decimals is normalized; one further from unit length is
// more likely a mistake (wrong order, a missing component) and is rejected.
constexpr double kQuaternionNormTolerance = 1e-2;

std::string location(const std::string& source, const YAML::Mark& mark) {
  if (mark.is_null()) return source;
  return fmt::format("{}:{}:{}", source, mark.line + 1, mark.column + 1);
}

std::string describe(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Scalar:
      return fmt::format("'{}'", node.Scalar());
    case YAML::NodeType::Sequence:
      return fmt::format("a list of {}", node.size());
    case YAML::NodeType::Map:
      return "a mapping";
    default:
      return "nothing";
  }
}

// Edit distance, to suggest the intended key for a typo.
std::size_t editDistance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// One mapping of the file: its keys in file order, checked for duplicates, and the keys the
// config asked for, so that everything else can be reported as unknown.
class Mapping {
 public:
  struct Entry {
    std::string key;
    YAML::Node key_node;
    YAML::Node value;
  };

  Mapping(const YAML::Node& node, std::string prefix, const std::string& source)
      : prefix_(std::move(prefix)), source_(source) {
    for (auto it = node.begin(); it != node.end(); ++it) {
      if (!it->first.IsScalar()) fail(it->first.Mark(), "", "keys must be plain names");
      const std::string key = it->first.Scalar();
      if (const Entry* earlier = find(key)) {
        fail(it->first.Mark(), key,
             fmt::format("appears twice (first on line {})", earlier->key_node.Mark().line + 1));
      }
      entries_.push_back({key, it->first, it->second});
    }
  }

  /// The value of `key` if the file has it; remembers `key` as known either way.
  std::optional<YAML::Node> take(std::string_view key) {
    known_.emplace_back(key);
    if (const Entry* entry = find(key)) return entry->value;
    return std::nullopt;
  }

  void rejectUnknownKeys() const {
    for (const Entry& entry : entries_) {
      if (std::find(known_.begin(), known_.end(), entry.key) != known_.end()) continue;
      for (const MovedConfigKey& moved : movedConfigKeys()) {
        if (moved.old_key == prefix_ + entry.key)
          fail(entry.key_node.Mark(), entry.key,
               fmt::format("moved to {} ({})", moved.new_key, moved.why));
      }
      std::string hint;
      std::size_t best = entry.key.size() / 3 + 2;  // suggest only plausible typos
      for (const std::string& candidate : known_) {
        const std::size_t d = editDistance(entry.key, candidate);
        if (d < best) {
          best = d;
          hint = fmt::format("did you mean '{}'? ", candidate);
        }
      }
      fail(entry.key_node.Mark(), entry.key,
           fmt::format("unknown key; {}valid keys here: {}", hint, fmt::join(known_, ", ")));
    }
  }

  /// Where `key` is in the file, for errors found after reading (validation).
  YAML::Mark markOf(std::string_view key) const {
    const Entry* entry = find(key);
    return entry ? entry->key_node.Mark() : YAML::Mark::null_mark();
  }

  [[noreturn]] void fail(const YAML::Mark& mark, std::string_view key,
                         const std::string& problem) const {
    throw InputError(fmt::format("{}: {}{}: {}", location(source_, mark), prefix_, key, problem));
  }
  const std::string& prefix() const { return prefix_; }
  const std::string& source() const { return source_; }

 private:
  const Entry* find(std::string_view key) const {
    for (const Entry& entry : entries_) {
      if (entry.key == key) return &entry;
    }
    return nullptr;
  }

  std::string prefix_;
  const std::string& source_;
  std::vector<Entry> entries_;
  std::vector<std::string> known_;
};

double parseNumber(const Mapping& m, std::string_view key, const YAML::Node& node,
                   std::string_view doc) {
  double value = 0.0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, value) || !std::isfinite(value)) {
    m.fail(node.Mark(), key,
           fmt::format("expected a finite number ({}), got {}", doc, describe(node)));
  }
  return value;
}

std::vector<double> parseNumbers(const Mapping& m, std::string_view key, const YAML::Node& node,
                                 std::size_t count, std::string_view layout) {
  if (!node.IsSequence() || node.size() != count) {
    m.fail(node.Mark(), key,
           fmt::format("expected a list of {} numbers {}, got {}", count, layout, describe(node)));
  }
  std::vector<double> values;
  for (const YAML::Node& element : node) values.push_back(parseNumber(m, key, element, layout));
  return values;
}

// A rigid transform: translation_m [x, y, z] plus either quaternion_xyzw [x, y, z, w] or
// rpy_deg [roll, pitch, yaw]; parts not given keep their current value.
lie::SE3 parsePose(const Mapping& parent, std::string_view key, const YAML::Node& node,
                   const lie::SE3& current) {
  if (!node.IsMap()) {
    parent.fail(node.Mark(), key,
                fmt::format("expected a mapping with translation_m and quaternion_xyzw or rpy_deg, "
                            "got {}",
                            describe(node)));
  }
  Mapping m(node, parent.prefix() + std::string(key) + ".", parent.source());
  Eigen::Vector3d translation = current.translation();
  lie::SO3 rotation = current.rotation();
  if (auto t = m.take("translation_m")) {
    const auto v = parseNumbers(m, "translation_m", *t, 3, "[x, y, z] in m");
    translation = Eigen::Vector3d(v[0], v[1], v[2]);
  }
  const auto quaternion = m.take("quaternion_xyzw");
  const auto rpy = m.take("rpy_deg");
  m.rejectUnknownKeys();
  if (quaternion && rpy) {
    m.fail(rpy->Mark(), "rpy_deg",
           "give the rotation either as quaternion_xyzw or as rpy_deg, not both");
  }
  if (quaternion) {
    const auto v = parseNumbers(m, "quaternion_xyzw", *quaternion, 4, "[x, y, z, w]");
    const Eigen::Quaterniond q(v[3], v[0], v[1], v[2]);
    if (std::abs(q.norm() - 1.0) > kQuaternionNormTolerance) {
      m.fail(
          quaternion->Mark(), "quaternion_xyzw",
          fmt::format("expected a unit quaternion in x, y, z, w order, got norm {:.4f}", q.norm()));
    }
    rotation = lie::SO3(q);
  }
  if (rpy) {
    const auto v = parseNumbers(m, "rpy_deg", *rpy, 3, "[roll, pitch, yaw] in degrees");
    rotation = lie::SO3::fromRollPitchYaw(v[0] * kRadPerDeg, v[1] * kRadPerDeg, v[2] * kRadPerDeg);
  }
  return lie::SE3(rotation, translation);
}

// A list of boxes, each {min_m: [x, y, z], max_m: [x, y, z]} with min <= max on every axis; an
// empty list or null is no box.
std::vector<Box> parseBoxes(const Mapping& parent, std::string_view key, const YAML::Node& node) {
  std::vector<Box> boxes;
  if (node.IsNull()) return boxes;
  if (!node.IsSequence()) {
    parent.fail(node.Mark(), key,
                fmt::format("expected a list of boxes {{min_m: [x, y, z], max_m: [x, y, z]}}, got {}",
                            describe(node)));
  }
  for (std::size_t i = 0; i < node.size(); ++i) {
    const YAML::Node& entry = node[i];
    const std::string entry_key = fmt::format("{}[{}]", key, i);
    if (!entry.IsMap()) {
      parent.fail(entry.Mark(), entry_key,
                  fmt::format("expected a mapping with min_m and max_m, got {}", describe(entry)));
    }
    Mapping m(entry, parent.prefix() + entry_key + ".", parent.source());
    const auto min_node = m.take("min_m");
    const auto max_node = m.take("max_m");
    m.rejectUnknownKeys();
    Box box;
    for (auto [name, node_of_corner, corner] :
         {std::tuple{"min_m", &min_node, &box.min_m}, {"max_m", &max_node, &box.max_m}}) {
      if (!*node_of_corner) m.fail(entry.Mark(), name, "missing: every box needs min_m and max_m");
      const auto v = parseNumbers(m, name, **node_of_corner, 3, "[x, y, z] in m");
      *corner = Eigen::Vector3d(v[0], v[1], v[2]);
    }
    if (!(box.min_m.array() <= box.max_m.array()).all()) {
      m.fail(entry.Mark(), "max_m", "expected max_m >= min_m on every axis");
    }
    boxes.push_back(box);
  }
  return boxes;
}

class YamlReader final : public ConfigVisitor {
 public:
  YamlReader(const YAML::Node& node, std::string prefix, const std::string& source)
      : mapping_(node, std::move(prefix), source) {}

  void read(ConfigSection& section) {
    section.visit(*this);
    mapping_.rejectUnknownKeys();
    try {
      section.validate();
    } catch (const ConfigError& e) {
      const std::string first_key = e.key().substr(0, e.key().find('.'));
      throw InputError(fmt::format("{}: {}{}: {}",
                                   location(mapping_.source(), mapping_.markOf(first_key)),
                                   mapping_.prefix(), e.key(), e.problem()));
    }
  }

  void field(std::string_view key, double& value, std::string_view doc) override {
    if (auto node = mapping_.take(key)) value = parseNumber(mapping_, key, *node, doc);
  }
  void field(std::string_view key, int& value, std::string_view) override {
    auto node = mapping_.take(key);
    if (node && (!node->IsScalar() || !YAML::convert<int>::decode(*node, value))) {
      mapping_.fail(node->Mark(), key, fmt::format("expected an integer, got {}", describe(*node)));
    }
  }
  void field(std::string_view key, bool& value, std::string_view) override {
    auto node = mapping_.take(key);
    if (node && (!node->IsScalar() || !YAML::convert<bool>::decode(*node, value))) {
      mapping_.fail(node->Mark(), key,
                    fmt::format("expected true or false, got {}", describe(*node)));
    }
  }
  void field(std::string_view key, std::string& value, std::string_view) override {
    auto node = mapping_.take(key);
    if (!node) return;
    if (!node->IsScalar())
      mapping_.fail(node->Mark(), key,
                    fmt::format("expected a text value, got {}", describe(*node)));
    value = node->Scalar();
  }
  void field(std::string_view key, Eigen::Vector3d& value, std::string_view doc) override {
    if (auto node = mapping_.take(key)) {
      const auto v = parseNumbers(mapping_, key, *node, 3, fmt::format("[x, y, z] ({})", doc));
      value = Eigen::Vector3d(v[0], v[1], v[2]);
    }
  }
  void field(std::string_view key, lie::SE3& value, std::string_view) override {
    if (auto node = mapping_.take(key)) value = parsePose(mapping_, key, *node, value);
  }
  void field(std::string_view key, std::vector<Box>& value, std::string_view) override {
    if (auto node = mapping_.take(key)) value = parseBoxes(mapping_, key, *node);
  }
  void choice(std::string_view key, std::string& value, std::span<const std::string_view> allowed,
              std::string_view) override {
    auto node = mapping_.take(key);
    if (!node) return;
    const bool valid = node->IsScalar() &&
                       std::find(allowed.begin(), allowed.end(), node->Scalar()) != allowed.end();
    if (!valid) {
      mapping_.fail(
          node->Mark(), key,
          fmt::format("expected one of {}, got {}", fmt::join(allowed, ", "), describe(*node)));
    }
    value = node->Scalar();
  }
  void section(std::string_view key, ConfigSection& value, std::string_view) override {
    auto node = mapping_.take(key);
    if (!node || node->IsNull()) return;
    if (!node->IsMap()) {
      mapping_.fail(node->Mark(), key,
                    fmt::format("expected a mapping of keys, got {}", describe(*node)));
    }
    YamlReader(*node, mapping_.prefix() + std::string(key) + ".", mapping_.source()).read(value);
  }

 private:
  Mapping mapping_;
};

class YamlWriter final : public ConfigVisitor {
 public:
  explicit YamlWriter(YAML::Emitter& out) : out_(out) {}

  void field(std::string_view key, double& value, std::string_view doc) override {
    scalar(key, detail::formatExact(value), doc);
  }
  void field(std::string_view key, int& value, std::string_view doc) override {
    scalar(key, std::to_string(value), doc);
  }
  void field(std::string_view key, bool& value, std::string_view doc) override {
    scalar(key, value ? "true" : "false", doc);
  }
  void field(std::string_view key, std::string& value, std::string_view doc) override {
    out_ << YAML::Key << std::string(key) << YAML::Value << YAML::DoubleQuoted << value
         << YAML::Comment(std::string(doc));
  }
  void field(std::string_view key, Eigen::Vector3d& value, std::string_view doc) override {
    out_ << YAML::Key << std::string(key) << YAML::Value;
    numbers({value.x(), value.y(), value.z()});
    out_ << YAML::Comment(std::string(doc));
  }
  void field(std::string_view key, lie::SE3& value, std::string_view doc) override {
    const Eigen::Quaterniond& q = value.rotation().quaternion();
    out_ << YAML::Key << std::string(key) << YAML::Comment(std::string(doc)) << YAML::Value
         << YAML::BeginMap;
    out_ << YAML::Key << "translation_m" << YAML::Value;
    numbers({value.translation().x(), value.translation().y(), value.translation().z()});
    out_ << YAML::Key << "quaternion_xyzw" << YAML::Value;
    numbers({q.x(), q.y(), q.z(), q.w()});
    out_ << YAML::EndMap;
  }
  void field(std::string_view key, std::vector<Box>& value, std::string_view doc) override {
    out_ << YAML::Key << std::string(key) << YAML::Comment(std::string(doc)) << YAML::Value
         << YAML::BeginSeq;
    for (const Box& box : value) {
      out_ << YAML::Flow << YAML::BeginMap << YAML::Key << "min_m" << YAML::Value;
      numbers({box.min_m.x(), box.min_m.y(), box.min_m.z()});
      out_ << YAML::Key << "max_m" << YAML::Value;
      numbers({box.max_m.x(), box.max_m.y(), box.max_m.z()});
      out_ << YAML::EndMap;
    }
    out_ << YAML::EndSeq;
  }
  void choice(std::string_view key, std::string& value, std::span<const std::string_view> allowed,
              std::string_view doc) override {
    scalar(key, value, fmt::format("{} (one of {})", doc, fmt::join(allowed, ", ")));
  }
  void section(std::string_view key, ConfigSection& value, std::string_view doc) override {
    out_ << YAML::Key << std::string(key) << YAML::Comment(std::string(doc)) << YAML::Value
         << YAML::BeginMap;
    value.visit(*this);
    out_ << YAML::EndMap;
  }

 private:
  void scalar(std::string_view key, const std::string& text, std::string_view doc) {
    out_ << YAML::Key << std::string(key) << YAML::Value << text << YAML::Comment(std::string(doc));
  }
  void numbers(std::initializer_list<double> values) {
    out_ << YAML::Flow << YAML::BeginSeq;
    for (double v : values) out_ << detail::formatExact(v);
    out_ << YAML::EndSeq;
  }

  YAML::Emitter& out_;
};

}  // namespace

void readConfigYamlText(std::string_view text, std::string_view source_name,
                        ConfigSection& config) {
  const std::string source(source_name);
  YAML::Node root;
  try {
    root = YAML::Load(std::string(text));
  } catch (const YAML::Exception& e) {
    throw InputError(fmt::format("{}: YAML syntax error: {}", location(source, e.mark), e.msg));
  }
  if (root.IsDefined() && !root.IsNull()) {
    if (!root.IsMap()) {
      throw InputError(fmt::format("{}: expected a mapping of sections at the top level, got {}",
                                   location(source, root.Mark()), describe(root)));
    }
    YamlReader(root, "", source).read(config);
  }
  // Sections the file did not mention were not checked while reading.
  try {
    validateAll(config);
  } catch (const ConfigError& e) {
    throw InputError(fmt::format("{}: {}", source, e.what()));
  }
}

void readConfigYaml(const std::filesystem::path& path, ConfigSection& config) {
  if (!std::filesystem::is_regular_file(path)) {
    throw InputError(
        fmt::format("{}: {}", path.string(),
                    std::filesystem::exists(path) ? "is not a regular file" : "no such file"));
  }
  std::ifstream stream(path);
  std::stringstream text;
  text << stream.rdbuf();
  if (!stream) throw InputError(fmt::format("{}: cannot read", path.string()));
  readConfigYamlText(text.str(), path.string(), config);
}

std::string writeConfigYaml(ConfigSection& config) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  YamlWriter writer(out);
  config.visit(writer);
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace taiga::io
