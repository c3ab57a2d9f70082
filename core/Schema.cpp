#include "core/Schema.hpp"

#include "core/Suggest.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace mfsi {

// ---------------------------------------------------------------------------------------------
// Defaults

std::string formatReal(double v) {
  char buf[32];
  for (int precision : {15, 16, 17}) {
    std::snprintf(buf, sizeof(buf), "%.*g", precision, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

namespace {
std::string singleQuoted(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += (c == '\'') ? std::string("''") : std::string(1, c);
  return q + "'";
}
}  // namespace

Default::Default(double v) : yaml(formatReal(v)) {}
Default::Default(int v) : yaml(std::to_string(v)) {}
Default::Default(bool v) : yaml(v ? "true" : "false") {}
Default::Default(const char* s) : yaml(singleQuoted(s)) {}
Default::Default(const std::string& s) : yaml(singleQuoted(s)) {}

Default Default::fromYaml(std::string text) {
  Default d;
  d.yaml = std::move(text);
  return d;
}

std::string Default::flowList(const std::vector<double>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + formatReal(v[i]);
  return s + "]";
}

// ---------------------------------------------------------------------------------------------
// Schema construction

Schema Schema::map(std::string doc) { return Schema(Kind::Map, std::move(doc)); }

Schema Schema::freeMap(std::string doc, const Schema& item) {
  Schema s(Kind::FreeMap, std::move(doc));
  s.item_ = std::make_shared<const Schema>(item);
  return s;
}

Schema Schema::list(std::string doc, const Schema& item, int minLength) {
  Schema s(Kind::List, std::move(doc));
  s.item_ = std::make_shared<const Schema>(item);
  s.minLength_ = minLength;
  return s;
}

Schema Schema::leaf(Kind kind, ScalarType type, std::string doc, std::string units, int size) {
  Schema s(kind, std::move(doc));
  s.type_ = type;
  s.units_ = std::move(units);
  s.size_ = size;
  return s;
}

Schema Schema::real(std::string doc, std::string units) {
  return leaf(Kind::Scalar, ScalarType::Real, std::move(doc), std::move(units), 0);
}
Schema Schema::integer(std::string doc, std::string units) {
  return leaf(Kind::Scalar, ScalarType::Int, std::move(doc), std::move(units), 0);
}
Schema Schema::boolean(std::string doc) { return leaf(Kind::Scalar, ScalarType::Bool, std::move(doc), "", 0); }
Schema Schema::string(std::string doc) { return leaf(Kind::Scalar, ScalarType::String, std::move(doc), "", 0); }

Schema Schema::path(std::string doc) {
  Schema s = leaf(Kind::Scalar, ScalarType::String, std::move(doc), "", 0);
  s.path_ = true;
  return s;
}
Schema Schema::choice(std::string doc, std::vector<std::string> choices) {
  Schema s = leaf(Kind::Scalar, ScalarType::Enum, std::move(doc), "", 0);
  s.choices_ = std::move(choices);
  return s;
}
Schema Schema::realVector(int n, std::string doc, std::string units) {
  return leaf(Kind::Vector, ScalarType::Real, std::move(doc), std::move(units), n);
}
Schema Schema::intVector(int n, std::string doc, std::string units) {
  return leaf(Kind::Vector, ScalarType::Int, std::move(doc), std::move(units), n);
}

bool Schema::fillableWithoutDefault() const {
  switch (kind_) {
    case Kind::Map:
      return std::none_of(keys_.begin(), keys_.end(), [](const Key& k) { return k.presence == Presence::Required; });
    case Kind::FreeMap:
      return true;
    case Kind::List:
      return minLength_ == 0;
    default:
      return false;
  }
}

Schema& Schema::key(const std::string& name, const Schema& child, Presence presence) {
  auto fail = [&](const std::string& why) { throw std::logic_error("schema: key '" + name + "': " + why); };
  if (kind_ != Kind::Map) fail("keys can only be declared on a Map schema");
  if (findKey(name)) fail("declared twice");
  if (name.empty() || name.find('.') != std::string::npos) fail("key names must be non-empty and contain no '.'");
  if (presence == Presence::Optional && !child.fillableWithoutDefault())
    fail("an Optional " + child.typeName() + " needs a Default (or use Presence::OptionalSection)");
  keys_.push_back(Key{name, std::make_shared<const Schema>(child), presence, nullptr, ""});
  return *this;
}

Schema& Schema::key(const std::string& name, const Schema& child, const Default& value) {
  key(name, child, Presence::Required);
  Key& k = keys_.back();
  k.presence = Presence::Optional;
  k.defaultYaml = value.yaml;
  try {
    auto node = std::make_shared<detail::ConfigNode>(detail::parseYaml(value.yaml, "<schema default>", false));
    detail::validate(*node, *k.schema, name);
    k.defaultValue = node;
  } catch (const InputError& e) {
    keys_.pop_back();
    throw std::logic_error(std::string("schema: invalid default: ") + e.what());
  }
  return *this;
}

Schema& Schema::bound(double v, bool isMin, bool exclusive) {
  const bool numeric =
      (kind_ == Kind::Scalar || kind_ == Kind::Vector) && (type_ == ScalarType::Real || type_ == ScalarType::Int);
  if (!numeric) throw std::logic_error("schema: bounds on a non-numeric value (" + doc_ + ")");
  (isMin ? bounds_.min : bounds_.max) = v;
  (isMin ? bounds_.minExclusive : bounds_.maxExclusive) = exclusive;
  return *this;
}

Schema& Schema::greaterThan(double v) { return bound(v, true, true); }
Schema& Schema::atLeast(double v) { return bound(v, true, false); }
Schema& Schema::lessThan(double v) { return bound(v, false, true); }
Schema& Schema::atMost(double v) { return bound(v, false, false); }

const Schema::Key* Schema::findKey(const std::string& name) const {
  for (const auto& k : keys_)
    if (k.name == name) return &k;
  return nullptr;
}

std::vector<std::string> Schema::keyNames() const {
  std::vector<std::string> names;
  for (const auto& k : keys_) names.push_back(k.name);
  return names;
}

std::string Schema::typeName() const {
  const bool isInt = type_ == ScalarType::Int;
  switch (kind_) {
    case Kind::Map:
      return "a map";
    case Kind::FreeMap:
      return "a map of named entries";
    case Kind::List:
      return "a list";
    case Kind::Vector:
      return "a list of " + std::to_string(size_) + (isInt ? " integers" : " real numbers");
    case Kind::Scalar:
      break;
  }
  switch (type_) {
    case ScalarType::Real:
      return "a real number";
    case ScalarType::Int:
      return "an integer";
    case ScalarType::Bool:
      return "true or false";
    case ScalarType::String:
      return "a string";
    case ScalarType::Enum:
      return "one of " + joinList(choices_);
  }
  return "";
}

std::string Schema::boundsText() const {
  std::string s;
  if (bounds_.min) s += (bounds_.minExclusive ? "> " : ">= ") + formatReal(*bounds_.min);
  if (bounds_.max)
    s += (s.empty() ? "" : " and ") + std::string(bounds_.maxExclusive ? "< " : "<= ") + formatReal(*bounds_.max);
  return s;
}

// ---------------------------------------------------------------------------------------------
// Documentation

namespace {
void describe(const Schema& s, const std::string& label, const std::string& extra, int depth, std::ostringstream& os) {
  std::string head = std::string(2 * depth, ' ') + label;
  std::string info = s.typeName();
  if (!extra.empty()) info += ", " + extra;
  if (!s.boundsText().empty()) info += ", " + s.boundsText();
  if (!s.units().empty()) info += ", units " + s.units();
  if (s.kind() == Schema::Kind::List && s.minLength() > 0) info += ", at least " + std::to_string(s.minLength());
  os << head << std::string(head.size() < 32 ? 32 - head.size() : 1, ' ') << "(" << info << ")";
  if (!s.doc().empty()) os << "  " << s.doc();
  os << "\n";
  switch (s.kind()) {
    case Schema::Kind::Map:
      for (const auto& k : s.keys()) {
        std::string presence = k.presence == Presence::Required          ? "required"
                               : k.presence == Presence::OptionalSection ? "optional section"
                               : k.defaultValue                          ? "default " + k.defaultYaml
                                                                         : "optional";
        describe(*k.schema, k.name + ":", presence, depth + 1, os);
      }
      break;
    case Schema::Kind::FreeMap:
      describe(s.item(), "<name>:", "", depth + 1, os);
      break;
    case Schema::Kind::List:
      describe(s.item(), "- item:", "", depth + 1, os);
      break;
    default:
      break;
  }
}
}  // namespace

std::string describeSchema(const Schema& schema) {
  std::ostringstream os;
  describe(schema, "scene:", "", 0, os);
  return os.str();
}

// ---------------------------------------------------------------------------------------------
// Parsing

namespace detail {

const ConfigNode* ConfigNode::find(const std::string& key) const {
  for (const auto& c : items)
    if (c.name == key) return &c;
  return nullptr;
}

ConfigNode* ConfigNode::find(const std::string& key) {
  return const_cast<ConfigNode*>(static_cast<const ConfigNode*>(this)->find(key));
}

namespace {
SourceLocation locationOf(const YAML::Mark& m, const std::string& file, bool withMarks) {
  SourceLocation l;
  l.file = file;
  if (withMarks && !m.is_null() && m.line >= 0) {
    l.line = m.line + 1;
    l.column = m.column + 1;
  }
  return l;
}

/// Values a scene may expand to: far above any real scene (thousands), far below what YAML aliases
/// nested a few levels deep can make of a kilobyte (each level multiplies).
constexpr std::size_t kMaxSceneValues = 1000000;

ConfigNode convert(const YAML::Node& y, const std::string& file, bool withMarks, const SourceLocation& keyLoc,
                   std::size_t& values) {
  if (++values > kMaxSceneValues)
    throw InputError(locationOf(y.Mark(), file, withMarks),
                     "the scene expands to more than " + std::to_string(kMaxSceneValues) +
                         " values (YAML aliases nested inside each other?)");
  ConfigNode n;
  n.keyLoc = keyLoc;
  // yaml-cpp puts an empty value's mark on the next token, so an empty value points at its key.
  n.loc = y.IsNull() && keyLoc.line > 0 ? keyLoc : locationOf(y.Mark(), file, withMarks);
  switch (y.Type()) {
    case YAML::NodeType::Scalar:
      n.kind = ConfigNode::Kind::Scalar;
      n.text = y.Scalar();
      n.quoted = y.Tag() == "!";
      break;
    case YAML::NodeType::Sequence:
      n.kind = ConfigNode::Kind::List;
      // A list item's "key" is the item itself: errors about a whole item point at its first line.
      for (const auto& item : y)
        n.items.push_back(convert(item, file, withMarks, locationOf(item.Mark(), file, withMarks), values));
      break;
    case YAML::NodeType::Map:
      n.kind = ConfigNode::Kind::Map;
      for (auto it = y.begin(); it != y.end(); ++it) {
        SourceLocation kl = locationOf(it->first.Mark(), file, withMarks);
        if (!it->first.IsScalar()) throw InputError(kl, "map keys must be plain names");
        const std::string name = it->first.Scalar();
        if (n.find(name)) {
          kl.key = name;
          throw InputError(kl, "duplicate key");
        }
        n.items.push_back(convert(it->second, file, withMarks, kl, values));
        n.items.back().name = name;
      }
      break;
    default:
      break;
  }
  return n;
}
}  // namespace

ConfigNode parseYaml(const std::string& text, const std::string& file, bool withMarks) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    SourceLocation l = locationOf(e.mark, file, true);
    if (!withMarks) l.line = l.column = 0;
    throw InputError(l, "YAML syntax error: " + e.msg);
  }
  SourceLocation start{file, withMarks ? 1 : 0, withMarks ? 1 : 0, ""};
  std::size_t values = 0;
  ConfigNode n = convert(root, file, withMarks, SourceLocation{file, 0, 0, ""}, values);
  if (n.loc.line == 0) n.loc = start;  // empty document
  return n;
}

// ---------------------------------------------------------------------------------------------
// Validation

double parseReal(const std::string& text) { return std::strtod(text.c_str(), nullptr); }
long long parseInt(const std::string& text) { return std::strtoll(text.c_str(), nullptr, 10); }

namespace {
std::string join(const std::string& path, const std::string& name) { return path.empty() ? name : path + "." + name; }

SourceLocation at(const SourceLocation& l, const std::string& path) {
  SourceLocation r = l;
  r.key = path;
  return r;
}

std::string got(const ConfigNode& n) {
  switch (n.kind) {
    case ConfigNode::Kind::Null:
      return "an empty value";
    case ConfigNode::Kind::List:
      return "a list";
    case ConfigNode::Kind::Map:
      return "a map";
    case ConfigNode::Kind::Scalar:
      break;
  }
  return n.quoted ? "the quoted string '" + n.text + "'" : "'" + n.text + "'";
}

bool isNonFiniteSpelling(std::string t) {
  for (auto& c : t) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (!t.empty() && (t[0] == '+' || t[0] == '-')) t.erase(0, 1);
  return t == ".nan" || t == ".inf" || t == "nan" || t == "inf" || t == "infinity";
}

/// Check one scalar value; `what` prefixes the message (e.g. "item 2: ").
void checkScalar(const ConfigNode& n, const Schema& s, const SourceLocation& where, const std::string& what) {
  auto fail = [&](const std::string& msg) { throw InputError(where, what + msg); };
  if (n.kind != ConfigNode::Kind::Scalar) fail("expected " + s.typeName() + ", got " + got(n));
  const std::string& t = n.text;
  const bool numeric = s.scalarType() == ScalarType::Real || s.scalarType() == ScalarType::Int;
  if ((numeric || s.scalarType() == ScalarType::Bool) && n.quoted)
    fail("expected " + s.typeName() + ", got " + got(n) + " (remove the quotes)");
  double value = 0;
  switch (s.scalarType()) {
    case ScalarType::Real: {
      if (isNonFiniteSpelling(t)) fail("expected a finite real number, got '" + t + "'");
      char* end = nullptr;
      value = std::strtod(t.c_str(), &end);
      if (t.empty() || *end != '\0' || t.find_first_of("xX") != std::string::npos)
        fail("expected a real number, got '" + t + "'");
      if (!std::isfinite(value)) fail("expected a finite real number, got '" + t + "'");
      break;
    }
    case ScalarType::Int: {
      char* end = nullptr;
      errno = 0;
      const long long v = std::strtoll(t.c_str(), &end, 10);
      if (t.empty() || *end != '\0') fail("expected an integer, got '" + t + "'");
      if (errno == ERANGE || v < INT_MIN || v > INT_MAX) fail("integer '" + t + "' is too large");
      value = static_cast<double>(v);
      break;
    }
    case ScalarType::Bool:
      if (t != "true" && t != "false" && t != "True" && t != "False" && t != "TRUE" && t != "FALSE")
        fail("expected true or false, got '" + t + "'");
      return;
    case ScalarType::String:
      return;
    case ScalarType::Enum: {
      const auto& c = s.choices();
      if (std::find(c.begin(), c.end(), t) == c.end())
        fail("'" + t + "' is not allowed" + didYouMean(t, c) + "; choices: " + joinList(c));
      return;
    }
  }
  const auto& b = s.bounds();
  const bool tooLow = b.min && (b.minExclusive ? value <= *b.min : value < *b.min);
  const bool tooHigh = b.max && (b.maxExclusive ? value >= *b.max : value > *b.max);
  if (tooLow || tooHigh) fail("value " + t + " is out of range: must be " + s.boundsText());
}

/// The best place to point at for a map: its key in the parent if known.
const SourceLocation& anchor(const ConfigNode& n) { return n.keyLoc.line > 0 ? n.keyLoc : n.loc; }

/// Give a filled-in default the location of the map that received it.
void relocate(ConfigNode& n, const SourceLocation& l) {
  n.loc = n.keyLoc = l;
  n.defaulted = true;
  for (auto& c : n.items) relocate(c, l);
}
}  // namespace

void validate(ConfigNode& n, const Schema& s, const std::string& path) {
  n.schema = &s;
  const SourceLocation here = at(n.loc, path);
  switch (s.kind()) {
    case Schema::Kind::Scalar:
      checkScalar(n, s, here, "");
      return;
    case Schema::Kind::Vector: {
      if (n.kind != ConfigNode::Kind::List || static_cast<int>(n.items.size()) != s.size())
        throw InputError(here,
                         "expected " + s.typeName() + ", got " +
                             (n.kind == ConfigNode::Kind::List ? std::to_string(n.items.size()) + " items" : got(n)));
      for (std::size_t i = 0; i < n.items.size(); ++i) {
        n.items[i].schema = &s;
        checkScalar(n.items[i], s, here, "item " + std::to_string(i) + ": ");
      }
      return;
    }
    case Schema::Kind::List: {
      if (n.kind == ConfigNode::Kind::Null) n.kind = ConfigNode::Kind::List;
      if (n.kind != ConfigNode::Kind::List) throw InputError(here, "expected a list, got " + got(n));
      if (static_cast<int>(n.items.size()) < s.minLength())
        throw InputError(here, "needs at least " + std::to_string(s.minLength()) + " item(s), got " +
                                   std::to_string(n.items.size()));
      for (std::size_t i = 0; i < n.items.size(); ++i) validate(n.items[i], s.item(), join(path, std::to_string(i)));
      return;
    }
    case Schema::Kind::FreeMap:
    case Schema::Kind::Map:
      break;
  }
  // An empty value names a section with all its defaults (`fluid:`).
  if (n.kind == ConfigNode::Kind::Null) n.kind = ConfigNode::Kind::Map;
  if (n.kind != ConfigNode::Kind::Map) throw InputError(here, "expected " + s.typeName() + ", got " + got(n));
  if (s.kind() == Schema::Kind::FreeMap) {
    for (auto& c : n.items) {
      if (c.name.empty() || c.name.find('.') != std::string::npos)
        throw InputError(at(c.keyLoc, join(path, c.name)), "names must be non-empty and contain no '.'");
      validate(c, s.item(), join(path, c.name));
    }
    return;
  }
  for (const auto& c : n.items)
    if (!s.findKey(c.name))
      throw InputError(at(c.keyLoc, join(path, c.name)),
                       "unknown key" + didYouMean(c.name, s.keyNames()) + "; allowed keys: " + joinList(s.keyNames()));
  std::vector<ConfigNode> ordered;
  for (const auto& k : s.keys()) {
    ConfigNode* given = n.find(k.name);
    if (given) {
      ordered.push_back(std::move(*given));
    } else if (k.presence == Presence::Required) {
      throw InputError(at(anchor(n), join(path, k.name)),
                       "missing required key (" + k.schema->typeName() + ": " + k.schema->doc() + ")");
    } else if (k.presence == Presence::Optional) {
      ConfigNode filled = k.defaultValue ? *k.defaultValue : ConfigNode{};
      filled.name = k.name;
      relocate(filled, anchor(n));
      ordered.push_back(std::move(filled));
    } else {
      continue;
    }
    validate(ordered.back(), *k.schema, join(path, k.name));
  }
  n.items = std::move(ordered);
}

}  // namespace detail
}  // namespace mfsi
