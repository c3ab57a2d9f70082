#include "core/SceneConfig.hpp"

#include "core/Suggest.hpp"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>

namespace mfsi {

using detail::ConfigNode;

namespace {

std::string join(const std::string& path, const std::string& name) {
  return path.empty() ? name : name.empty() ? path : path + "." + name;
}

SourceLocation located(SourceLocation l, const std::string& key) {
  l.key = key;
  return l;
}

std::vector<std::string> splitPath(const std::string& path) {
  std::vector<std::string> parts;
  if (path.empty()) return parts;
  std::size_t start = 0;
  while (true) {
    const std::size_t dot = path.find('.', start);
    parts.push_back(path.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
    if (dot == std::string::npos) return parts;
    start = dot + 1;
  }
}

bool isIndex(const std::string& s) {
  return !s.empty() && s.size() < 9 && s.find_first_not_of("0123456789") == std::string::npos;
}

/// Mark a node created by an override (and its sub-tree) as coming from it.
void relocate(ConfigNode& n, const SourceLocation& l) {
  n.loc = n.keyLoc = l;
  for (auto& c : n.items) relocate(c, l);
}

/// One step of a dotted path through the schema, from `parent` (its dotted path) to `part`. `component`
/// is true once inside a Vector (its items are numbers). Calls `fail` (which throws) when the schema has
/// no such child.
const Schema* step(const Schema& s, bool& component, const std::string& parent, const std::string& part,
                   const std::function<void(const std::string&)>& fail) {
  if (part.empty()) fail("empty name in the key path");
  if (component || s.kind() == Schema::Kind::Scalar)
    fail("'" + parent + "' is " + s.typeName() + ", it has no sub-keys");
  switch (s.kind()) {
    case Schema::Kind::Map: {
      const Schema::Key* k = s.findKey(part);
      if (!k) fail("unknown key" + didYouMean(part, s.keyNames()) + "; allowed keys: " + joinList(s.keyNames()));
      return k->schema.get();
    }
    case Schema::Kind::FreeMap:
      return &s.item();
    case Schema::Kind::List:
    case Schema::Kind::Vector:
      if (!isIndex(part)) fail("'" + parent + "' is a list, '" + part + "' is not an item index (0, 1, ...)");
      if (s.kind() == Schema::Kind::Vector) {
        component = true;
        return &s;
      }
      return &s.item();
    case Schema::Kind::Scalar:
      break;
  }
  return nullptr;
}

/// Apply one `--set path=value` to the unvalidated tree: walk the schema and the tree together,
/// creating missing maps and list items, then replace the value.
void applyOverride(ConfigNode& root, const Schema& schema, const std::string& arg) {
  const SourceLocation src{"--set " + arg, 0, 0, ""};
  const std::size_t eq = arg.find('=');
  if (eq == std::string::npos || eq == 0) throw InputError(src, "expected --set key.path=value");
  const std::vector<std::string> parts = splitPath(arg.substr(0, eq));
  ConfigNode value = detail::parseYaml(arg.substr(eq + 1), src.file, false);

  ConfigNode* node = &root;
  const Schema* s = &schema;
  bool component = false;
  std::string path;
  for (const auto& part : parts) {
    const std::string parent = path;
    path = join(path, part);
    const bool list = s->kind() == Schema::Kind::List || s->kind() == Schema::Kind::Vector;
    const Schema::Key* key = s->kind() == Schema::Kind::Map ? s->findKey(part) : nullptr;
    s = step(*s, component, parent, part, [&](const std::string& msg) { throw InputError(located(src, path), msg); });
    if (node->kind == ConfigNode::Kind::Null) node->kind = list ? ConfigNode::Kind::List : ConfigNode::Kind::Map;
    const auto wantKind = list ? ConfigNode::Kind::List : ConfigNode::Kind::Map;
    if (node->kind != wantKind)
      throw InputError(located(node->loc, parent),
                       std::string("expected ") + (list ? "a list" : "a map") + " here to apply " + src.file);
    ConfigNode* next = nullptr;
    if (list) {
      const std::size_t i = std::stoul(part), n = node->items.size();
      if (i > n)
        throw InputError(located(src, path), "item " + part + " does not exist: '" + parent + "' has " +
                                                 std::to_string(n) + " item(s) (use index " + std::to_string(n) +
                                                 " to append)");
      if (i == n) {
        node->items.emplace_back();
        relocate(node->items.back(), src);
      }
      next = &node->items[i];
    } else {
      next = node->find(part);
      if (!next) {
        // Start from the default, so `--set mesh.size.2=0.5` changes one component of it.
        node->items.push_back(key && key->defaultValue ? *key->defaultValue : ConfigNode{});
        next = &node->items.back();
        next->name = part;
        relocate(*next, src);
      }
    }
    node = next;
  }
  if (parts.empty()) throw InputError(src, "expected --set key.path=value");
  const std::string name = node->name;
  *node = std::move(value);
  node->name = name;
  node->keyLoc = src;
}

/// `n` as YAML; a path (Schema::path) made absolute against `base`, the scene file's folder.
void emit(YAML::Emitter& e, const ConfigNode& n, bool commentDefaults, const std::filesystem::path& base) {
  switch (n.kind) {
    case ConfigNode::Kind::Null:
      e << YAML::Null;
      break;
    case ConfigNode::Kind::Scalar:
      if (n.schema && n.schema->isPath() && !n.text.empty() && std::filesystem::path(n.text).is_relative())
        e << std::filesystem::absolute(base / n.text).lexically_normal().string();
      else
        e << n.text;
      break;
    case ConfigNode::Kind::List: {
      const bool flat = std::all_of(n.items.begin(), n.items.end(),
                                    [](const ConfigNode& c) { return c.kind == ConfigNode::Kind::Scalar; });
      if (flat || n.items.empty()) e << YAML::Flow;
      e << YAML::BeginSeq;
      for (const auto& c : n.items) emit(e, c, commentDefaults, base);
      e << YAML::EndSeq;
      break;
    }
    case ConfigNode::Kind::Map:
      if (n.items.empty()) e << YAML::Flow;
      e << YAML::BeginMap;
      for (const auto& c : n.items) {
        e << YAML::Key << c.name << YAML::Value;
        emit(e, c, commentDefaults, base);
        const bool leaf = c.kind == ConfigNode::Kind::Scalar || c.items.empty() ||
                          (c.schema && c.schema->kind() == Schema::Kind::Vector);
        if (commentDefaults && c.defaulted && leaf) e << YAML::Comment("default");
      }
      e << YAML::EndMap;
      break;
  }
}

[[noreturn]] void programmerError(const std::string& path, const std::string& msg) {
  throw std::logic_error("SceneConfig: key '" + path + "': " + msg);
}

}  // namespace

// ---------------------------------------------------------------------------------------------

SceneConfig SceneConfig::fromString(const std::string& yaml, const std::string& fileName, const Schema& schema,
                                    const std::vector<std::string>& overrides) {
  SceneConfig c;
  c.schema_ = std::make_shared<const Schema>(schema);
  auto root = std::make_shared<ConfigNode>(detail::parseYaml(yaml, fileName));
  for (const auto& o : overrides) applyOverride(*root, *c.schema_, o);
  detail::validate(*root, *c.schema_, "");
  c.root_ = root;
  c.node_ = root.get();
  return c;
}

SceneConfig SceneConfig::load(const std::string& file, const Schema& schema,
                              const std::vector<std::string>& overrides) {
  // A scene is a regular file of modest size (a FIFO would block, /dev/zero never ends).
  constexpr std::uintmax_t kMaxSceneBytes = 16u << 20;
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw InputError("cannot open scene file '" + file + "': no such file");
  if (!std::filesystem::is_regular_file(file, ec))
    throw InputError("cannot open scene file '" + file + "': not a regular file");
  if (std::filesystem::file_size(file, ec) > kMaxSceneBytes)
    throw InputError("cannot open scene file '" + file + "': larger than 16 MB, not a scene");
  std::ifstream in(file);
  if (!in) throw InputError("cannot open scene file '" + file + "': " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  return fromString(text.str(), file, schema, overrides);
}

std::string SceneConfig::full(const std::string& path) const { return join(prefix_, path); }

const ConfigNode* SceneConfig::find(const std::string& path, const ConfigNode** deepest) const {
  const ConfigNode* n = node_;
  const Schema* s = n->schema;
  bool component = n->kind == ConfigNode::Kind::Scalar && s->kind() == Schema::Kind::Vector;
  std::string done;
  for (const auto& part : splitPath(path)) {
    const std::string parent = done;
    done = join(done, part);
    s = step(*s, component, full(parent), part, [&](const std::string& msg) { programmerError(full(done), msg); });
    if (!n) continue;  // keep checking the rest of the path against the schema
    if (deepest) *deepest = n;
    if (n->kind == ConfigNode::Kind::List) {
      const std::size_t i = std::stoul(part);
      n = i < n->items.size() ? &n->items[i] : nullptr;
    } else {
      n = n->find(part);
    }
  }
  if (deepest && n) *deepest = n;
  return n;
}

const ConfigNode& SceneConfig::at(const std::string& path) const {
  const ConfigNode* n = find(path);
  if (!n) programmerError(full(path), "is absent from the scene (check has() first)");
  return *n;
}

bool SceneConfig::has(const std::string& path) const { return find(path) != nullptr; }

std::size_t SceneConfig::size(const std::string& path) const {
  const ConfigNode& n = at(path);
  if (n.kind == ConfigNode::Kind::Scalar) programmerError(full(path), "is a single value, it has no size");
  return n.items.size();
}

std::vector<std::string> SceneConfig::keys(const std::string& path) const {
  const ConfigNode& n = at(path);
  if (n.kind != ConfigNode::Kind::Map) programmerError(full(path), "is not a map");
  std::vector<std::string> names;
  for (const auto& c : n.items) names.push_back(c.name);
  return names;
}

SceneConfig SceneConfig::child(const std::string& path) const {
  SceneConfig c = *this;
  c.node_ = &at(path);
  c.prefix_ = full(path);
  return c;
}

SourceLocation SceneConfig::where(const std::string& path) const {
  const ConfigNode* n = node_;
  const bool found = find(path, &n) != nullptr;
  // A value points at itself; a map or an absent value at the key that opens the closest section.
  const bool pointAtKey = !found || n->kind == ConfigNode::Kind::Map;
  return located(pointAtKey && n->keyLoc.line > 0 ? n->keyLoc : n->loc, full(path));
}

std::string SceneConfig::resolvedYaml(bool commentDefaults) const {
  YAML::Emitter e;
  emit(e, *node_, commentDefaults, std::filesystem::path(file()).parent_path());
  return std::string(e.c_str()) + "\n";
}

// ---------------------------------------------------------------------------------------------
// Typed reads

namespace {
ScalarType scalarTypeOf(const ConfigNode& n, const std::string& path) {
  if (n.kind != ConfigNode::Kind::Scalar || !n.schema) programmerError(path, "is not a single value");
  return n.schema->scalarType();
}

void expectType(const ConfigNode& n, const std::string& path, std::initializer_list<ScalarType> ok,
                const char* wanted) {
  const ScalarType t = scalarTypeOf(n, path);
  if (std::find(ok.begin(), ok.end(), t) == ok.end())
    programmerError(path, "is " + n.schema->typeName() + ", read as " + wanted);
}

/// The scalar items of a vector or of a list of scalars.
const std::vector<ConfigNode>& scalarItems(const ConfigNode& n, const std::string& path) {
  if (n.kind != ConfigNode::Kind::List) programmerError(path, "is not a list");
  for (const auto& c : n.items)
    if (c.kind != ConfigNode::Kind::Scalar) programmerError(path, "is not a list of single values");
  return n.items;
}
}  // namespace

void SceneConfig::read(const std::string& path, double& v) const {
  const ConfigNode& n = at(path);
  expectType(n, full(path), {ScalarType::Real, ScalarType::Int}, "a real number");
  v = detail::parseReal(n.text);
}

void SceneConfig::read(const std::string& path, int& v) const {
  const ConfigNode& n = at(path);
  expectType(n, full(path), {ScalarType::Int}, "an integer");
  v = static_cast<int>(detail::parseInt(n.text));
}

void SceneConfig::read(const std::string& path, bool& v) const {
  const ConfigNode& n = at(path);
  expectType(n, full(path), {ScalarType::Bool}, "a bool");
  v = n.text == "true" || n.text == "True" || n.text == "TRUE";
}

void SceneConfig::read(const std::string& path, std::string& v) const {
  const ConfigNode& n = at(path);
  expectType(n, full(path), {ScalarType::String, ScalarType::Enum}, "a string");
  v = n.text;
}

void SceneConfig::read(const std::string& path, std::vector<double>& v) const {
  v.clear();
  for (const auto& c : scalarItems(at(path), full(path))) {
    expectType(c, full(path), {ScalarType::Real, ScalarType::Int}, "real numbers");
    v.push_back(detail::parseReal(c.text));
  }
}

void SceneConfig::read(const std::string& path, std::vector<int>& v) const {
  v.clear();
  for (const auto& c : scalarItems(at(path), full(path))) {
    expectType(c, full(path), {ScalarType::Int}, "integers");
    v.push_back(static_cast<int>(detail::parseInt(c.text)));
  }
}

void SceneConfig::read(const std::string& path, std::vector<std::string>& v) const {
  v.clear();
  for (const auto& c : scalarItems(at(path), full(path))) {
    expectType(c, full(path), {ScalarType::String, ScalarType::Enum}, "strings");
    v.push_back(c.text);
  }
}

void SceneConfig::checkLength(const std::string& path, std::size_t n, std::size_t wanted) const {
  if (n != wanted)
    programmerError(full(path), "has " + std::to_string(n) + " items, read as an array of " + std::to_string(wanted));
}

namespace {
void flatten(const YAML::Node& n, const std::string& key, std::map<std::string, std::string>& out) {
  if (n.IsMap()) {
    for (const auto& kv : n) flatten(kv.second, key.empty() ? kv.first.as<std::string>() : key + "." + kv.first.as<std::string>(), out);
  } else if (n.IsSequence()) {
    for (std::size_t i = 0; i < n.size(); ++i) flatten(n[i], key + "." + std::to_string(i), out);
  } else {
    out[key] = n.IsNull() ? "null" : n.as<std::string>();
  }
}
}  // namespace

std::vector<std::string> sceneDifferences(const std::string& before, const std::string& after) {
  std::map<std::string, std::string> a, b;
  flatten(YAML::Load(before), "", a);
  flatten(YAML::Load(after), "", b);
  std::vector<std::string> out;
  auto value = [](const std::map<std::string, std::string>& m, const std::string& k) {
    const auto it = m.find(k);
    return it == m.end() ? std::string("(none)") : it->second;
  };
  std::map<std::string, bool> keys;
  for (const auto& kv : a) keys[kv.first] = true;
  for (const auto& kv : b) keys[kv.first] = true;
  for (const auto& kv : keys) {
    const std::string va = value(a, kv.first), vb = value(b, kv.first);
    if (va != vb) out.push_back(kv.first + ": " + va + " -> " + vb);
  }
  return out;
}

}  // namespace mfsi
