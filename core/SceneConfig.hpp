#pragma once
/// \file
/// \brief A validated scene: YAML file + `--set` overrides, checked against a `Schema`, defaults
/// filled, typed access by dotted path. Module config layers turn it into plain option structs;
/// solvers never see it.
///
/// \code
///   auto cfg = mfsi::SceneConfig::load("cases/cavity.yaml", sceneSchema(), {"fluid.viscosity=2e-3"});
///   if (cfg.has("fluid")) {
///     FluidOptions o;
///     o.viscosity = cfg.get<double>("fluid.viscosity");
///     o.cells = cfg.get<std::array<int, 3>>("mesh.cells");
///   }
///   for (std::size_t i = 0; i < cfg.size("membranes"); ++i) {
///     mfsi::SceneConfig m = cfg.child("membranes." + std::to_string(i));
///     if (m.get<double>("E") < m.get<double>("E_min"))
///       throw mfsi::InputError(m.where("E"), "must exceed E_min");  // "file:line:col: key 'membranes.1.E': ..."
///   }
/// \endcode
///
/// User errors (bad YAML, unknown key, wrong type, ...) throw `InputError` naming file, line, column and
/// key. Asking for a path the schema does not declare, for the wrong type, or for an absent value is a
/// programmer error and throws `std::logic_error`.
#include "core/Error.hpp"
#include "core/Schema.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace mfsi {

class SceneConfig {
 public:
  /// \brief Read, override, validate. `overrides` are the arguments of `--set`, each "a.b.c=value"
  /// with the value parsed as YAML (`mesh.cells=[8,8,1]`, `membranes.0.E=2e6`); intermediate maps
  /// are created, list index == length appends, a map value replaces the whole map.
  static SceneConfig load(const std::string& file, const Schema& schema,
                          const std::vector<std::string>& overrides = {});
  /// \brief Same from YAML text; `fileName` names it in error messages.
  static SceneConfig fromString(const std::string& yaml, const std::string& fileName, const Schema& schema,
                                const std::vector<std::string>& overrides = {});

  /// \brief True when the value exists (given or defaulted). False for an absent optional section.
  bool has(const std::string& path) const;

  /// \brief Typed value at a dotted path relative to this view. T is double (real or integer values),
  /// int, bool, std::string (strings and enum choices), std::array<double|int, N> (vectors) or
  /// std::vector<double|int|std::string> (vectors and lists of scalars).
  template <class T>
  T get(const std::string& path) const {
    T value{};
    read(path, value);
    return value;
  }

  /// \brief Number of items of a list or vector, or of entries of a map present in the scene.
  std::size_t size(const std::string& path = "") const;
  /// \brief Names of the entries of a map present in the scene (e.g. patch names of a free map).
  std::vector<std::string> keys(const std::string& path = "") const;
  /// \brief View of a sub-tree (a section, a list item "membranes.0", a free-map entry). Paths of the
  /// view are relative to it; its errors and where() still name the full key.
  SceneConfig child(const std::string& path) const;

  /// \brief Where a value sits, for semantic errors of module config layers. For a defaulted or
  /// absent value: the closest enclosing key the scene gives. The key is the full dotted path.
  SourceLocation where(const std::string& path = "") const;

  /// \brief The resolved scene (this view) as YAML, defaults filled, keys in schema order; filled
  /// defaults carry a "# default" comment unless `commentDefaults` is false. Reading it back gives
  /// the same configuration.
  std::string resolvedYaml(bool commentDefaults = true) const;

  /// \brief Scene file name as given to load()/fromString().
  const std::string& file() const { return root_->loc.file; }
  /// \brief Dotted path of this view ("" for the whole scene).
  const std::string& prefix() const { return prefix_; }

 private:
  SceneConfig() = default;
  /// The node at `path`, or null when absent; std::logic_error when the schema has no such path.
  /// `deepest` receives the deepest node of the path present in the scene.
  const detail::ConfigNode* find(const std::string& path, const detail::ConfigNode** deepest = nullptr) const;
  /// The node at `path`, which must be present.
  const detail::ConfigNode& at(const std::string& path) const;
  std::string full(const std::string& path) const;

  void read(const std::string& path, double& v) const;
  void read(const std::string& path, int& v) const;
  void read(const std::string& path, bool& v) const;
  void read(const std::string& path, std::string& v) const;
  void read(const std::string& path, std::vector<double>& v) const;
  void read(const std::string& path, std::vector<int>& v) const;
  void read(const std::string& path, std::vector<std::string>& v) const;
  template <class E, std::size_t N>
  void read(const std::string& path, std::array<E, N>& a) const {
    std::vector<E> v;
    read(path, v);
    checkLength(path, v.size(), N);
    std::copy(v.begin(), v.end(), a.begin());
  }
  void checkLength(const std::string& path, std::size_t n, std::size_t wanted) const;

  std::shared_ptr<const Schema> schema_;  ///< owns the schema tree the nodes point into
  std::shared_ptr<const detail::ConfigNode> root_;
  const detail::ConfigNode* node_ = nullptr;  ///< root of this view
  std::string prefix_;
};

/// \brief The keys whose values differ between two resolved scenes (YAML text), each as
/// "key: before -> after" ("(none)" for a key one of them lacks), in key order.
std::vector<std::string> sceneDifferences(const std::string& before, const std::string& after);

}  // namespace mfsi
