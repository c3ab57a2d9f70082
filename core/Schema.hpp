#pragma once
/// \file
/// \brief Declared schema of a scene file: a tree of maps, lists, scalars and fixed-size vectors, each
/// with a doc string and units. `SceneConfig` validates a YAML scene against it, fills defaults and
/// names file, line, column and dotted key in every error.
///
/// Example:
/// \code
///   using mfsi::Schema; using mfsi::Presence; using mfsi::Default;
///   Schema fluid = Schema::map("incompressible Navier-Stokes")
///       .key("viscosity", Schema::real("dynamic viscosity", "Pa s").greaterThan(0), Default(1e-3))
///       .key("scheme", Schema::choice("convection scheme", {"upwind", "central"}), Default("upwind"));
///   Schema scene = Schema::map("scene")
///       .key("mesh", Schema::map("mesh").key("cells", Schema::intVector(3, "cells per direction").atLeast(1)))
///       .key("fluid", fluid, Presence::OptionalSection)
///       .key("bc", Schema::freeMap("boundary conditions per patch", bcSchema), Presence::Optional);
/// \endcode
#include "core/Error.hpp"

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace mfsi {

/// \brief How a map key may be absent from a scene.
enum class Presence {
  Required,        ///< the scene must give it
  Optional,        ///< filled when absent: from its Default, or (maps) from the defaults of its keys,
                   ///< or (lists, free maps) empty
  OptionalSection  ///< stays absent unless the scene names it: its presence switches a module on
};

/// \brief Kind of a scalar value.
enum class ScalarType { Real, Int, Bool, String, Enum };

/// \brief A default value for `Schema::key`, kept as YAML text (validated when the key is declared).
struct Default {
  Default(double v);
  Default(int v);
  Default(bool v);
  Default(const char* s);
  Default(const std::string& s);
  template <std::size_t N>
  Default(const std::array<double, N>& v) : yaml(flowList(std::vector<double>(v.begin(), v.end()))) {}
  template <std::size_t N>
  Default(const std::array<int, N>& v) : yaml(flowList(std::vector<double>(v.begin(), v.end()))) {}
  /// Any YAML text, e.g. `Default::fromYaml("[{E: 1e6}]")`.
  static Default fromYaml(std::string text);

  std::string yaml;

 private:
  Default() = default;
  static std::string flowList(const std::vector<double>& v);
};

/// \brief Shortest decimal text that reads back to exactly `v`.
std::string formatReal(double v);

namespace detail {
struct ConfigNode;
}

/// \brief One node of a scene schema. Immutable children are shared, so copies are cheap.
class Schema {
 public:
  enum class Kind {
    Map,      ///< fixed keys, each with its own schema
    FreeMap,  ///< user-chosen keys (e.g. patch names), each validated against one item schema
    List,     ///< any number of items of one schema
    Scalar,   ///< one real, integer, bool, string or enum value
    Vector    ///< fixed-length list of reals or integers, e.g. a point or cell counts
  };

  /// \brief A declared key of a Map.
  struct Key {
    std::string name;
    std::shared_ptr<const Schema> schema;
    Presence presence = Presence::Required;
    std::shared_ptr<const detail::ConfigNode> defaultValue;  ///< null when there is no Default
    std::string defaultYaml;                                 ///< for documentation
  };

  /// \brief Optional numeric bounds of a Real/Int scalar or of every vector component.
  struct Bounds {
    std::optional<double> min, max;
    bool minExclusive = false, maxExclusive = false;
  };

  static Schema map(std::string doc);
  static Schema freeMap(std::string doc, const Schema& item);
  static Schema list(std::string doc, const Schema& item, int minLength = 0);
  static Schema real(std::string doc, std::string units);
  static Schema integer(std::string doc, std::string units = "-");
  static Schema boolean(std::string doc);
  static Schema string(std::string doc);
  /// A file or folder path, relative to the scene file's folder when not absolute: a string that
  /// SceneConfig::resolvedYaml writes absolute, so a copy of the scene elsewhere (a run's
  /// scene.yaml) names the same file.
  static Schema path(std::string doc);
  static Schema choice(std::string doc, std::vector<std::string> choices);
  static Schema realVector(int n, std::string doc, std::string units);
  static Schema intVector(int n, std::string doc, std::string units = "-");

  /// Declare a key of a Map. Throws std::logic_error on schema bugs (duplicate key, Optional scalar
  /// without a Default, Optional map with a required key).
  Schema& key(const std::string& name, const Schema& child, Presence presence = Presence::Required);
  /// Declare an Optional key with a default value (validated here; a bad default is a logic_error).
  Schema& key(const std::string& name, const Schema& child, const Default& value);

  /// Bounds of a Real/Int scalar or vector (per component).
  Schema& greaterThan(double v);
  Schema& atLeast(double v);
  Schema& lessThan(double v);
  Schema& atMost(double v);

  Kind kind() const { return kind_; }
  ScalarType scalarType() const { return type_; }
  bool isPath() const { return path_; }
  const std::string& doc() const { return doc_; }
  const std::string& units() const { return units_; }
  const std::vector<Key>& keys() const { return keys_; }
  const Key* findKey(const std::string& name) const;
  std::vector<std::string> keyNames() const;
  /// Item schema of a List or FreeMap.
  const Schema& item() const { return *item_; }
  int minLength() const { return minLength_; }
  /// Length of a Vector.
  int size() const { return size_; }
  const std::vector<std::string>& choices() const { return choices_; }
  const Bounds& bounds() const { return bounds_; }
  /// True when an Optional key of this schema can be filled without a Default (all keys optional).
  bool fillableWithoutDefault() const;

  /// "a real number", "an integer", "a list of 3 real numbers", "a map", ... for messages.
  std::string typeName() const;
  /// "> 0 and <= 1", or "" without bounds.
  std::string boundsText() const;

 private:
  Schema(Kind k, std::string doc) : kind_(k), doc_(std::move(doc)) {}
  static Schema leaf(Kind kind, ScalarType type, std::string doc, std::string units, int size);
  Schema& bound(double v, bool isMin, bool exclusive);

  Kind kind_;
  ScalarType type_ = ScalarType::String;
  std::string doc_, units_;
  std::vector<Key> keys_;
  std::shared_ptr<const Schema> item_;
  int minLength_ = 0;
  int size_ = 0;
  bool path_ = false;
  std::vector<std::string> choices_;
  Bounds bounds_;
};

/// \brief Human-readable listing of every key: type, presence or default, bounds, units and doc
/// (for `mfsi check --describe`).
std::string describeSchema(const Schema& schema);

namespace detail {

/// \brief Parsed YAML with source locations, validated in place (internal to the config layer).
struct ConfigNode {
  enum class Kind { Null, Scalar, List, Map };
  Kind kind = Kind::Null;
  std::string text;                ///< scalar text
  bool quoted = false;             ///< scalar was quoted in the YAML ("1" is a string, not a number)
  std::string name;                ///< key in the parent map
  std::vector<ConfigNode> items;   ///< list items or map entries, in order
  SourceLocation loc;              ///< where the value sits (its `key` is unused)
  SourceLocation keyLoc;           ///< where its key sits in the parent map
  bool defaulted = false;          ///< filled from the schema, not given by the scene
  const Schema* schema = nullptr;  ///< set by validate()

  const ConfigNode* find(const std::string& key) const;
  ConfigNode* find(const std::string& key);
};

/// Parse YAML text; `file` names the source in locations. Throws InputError on syntax errors and
/// duplicate keys. With `withMarks = false` every node gets location `{file, 0, 0}` (for --set values).
ConfigNode parseYaml(const std::string& text, const std::string& file, bool withMarks = true);

/// Check `node` against `schema`, fill defaults, order map keys as declared. `path` is the dotted key
/// of `node` ("" for the root). Throws InputError naming file, line, column and key.
void validate(ConfigNode& node, const Schema& schema, const std::string& path);

/// Parse a validated Real/Int scalar text.
double parseReal(const std::string& text);
long long parseInt(const std::string& text);

}  // namespace detail

}  // namespace mfsi
