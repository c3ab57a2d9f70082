// Strict YAML scene configuration: schema, validation errors with file:line:column and key, defaults,
// optional sections, free maps, lists, --set overrides, resolved YAML round trip, documentation.
#include "core/Error.hpp"
#include "core/SceneConfig.hpp"
#include "core/Schema.hpp"
#include "support/Approx.hpp"

#include <filesystem>
#include <gtest/gtest.h>

#include <array>
#include <stdexcept>
#include <string>
#include <vector>

using mfsi::Default;
using mfsi::InputError;
using mfsi::Presence;
using mfsi::SceneConfig;
using mfsi::Schema;
using mfsi::test::near;
using mfsi::test::Tol;

namespace {

Schema testSchema() {
  Schema mesh =
      Schema::map("structured box mesh")
          .key("cells", Schema::intVector(3, "cells per direction").atLeast(1))
          .key("size", Schema::realVector(3, "box size", "m").greaterThan(0), Default(std::array<double, 3>{1, 1, 1}));
  Schema time = Schema::map("time stepping")
                    .key("dt", Schema::real("time step", "s").greaterThan(0), Default(1e-3))
                    .key("end", Schema::real("end time", "s").atLeast(0), Default(1.0))
                    .key("steps", Schema::integer("maximum steps").atLeast(1), Default(10));
  Schema fluid =
      Schema::map("incompressible fluid")
          .key("viscosity", Schema::real("dynamic viscosity", "Pa s").greaterThan(0))
          .key("density", Schema::real("density", "kg/m^3").greaterThan(0), Default(1000.0))
          .key("scheme", Schema::choice("convection scheme", {"upwind", "central", "quick"}), Default("upwind"))
          .key("verbose", Schema::boolean("log iterations"), Default(false));
  Schema membrane = Schema::map("one membrane")
                        .key("E", Schema::real("Young's modulus", "Pa").greaterThan(0))
                        .key("nu", Schema::real("Poisson ratio", "-").atLeast(0).lessThan(0.5), Default(0.3));
  Schema bc =
      Schema::map("boundary condition of one patch")
          .key("type", Schema::choice("kind", {"wall", "inlet", "outlet", "slip"}))
          .key("velocity", Schema::realVector(3, "inlet velocity", "m/s"), Default(std::array<double, 3>{0, 0, 0}));
  return Schema::map("test scene")
      .key("name", Schema::string("case name"), Default("demo"))
      .key("mesh", mesh)
      .key("time", time, Presence::Optional)
      .key("fluid", fluid, Presence::OptionalSection)
      .key("membranes", Schema::list("membranes", membrane), Presence::Optional)
      .key("boundary", Schema::freeMap("boundary conditions per patch", bc), Presence::Optional)
      .key("probes", Schema::list("probe positions", Schema::real("x position", "m")), Presence::Optional)
      .key("tags", Schema::list("labels", Schema::string("label"), 1), Presence::OptionalSection);
}

const char* kMinimal = "mesh:\n  cells: [4, 4, 1]\n";

SceneConfig parse(const std::string& yaml, const std::vector<std::string>& overrides = {}) {
  return SceneConfig::fromString(yaml, "cases/test.yaml", testSchema(), overrides);
}

/// The InputError message of loading `yaml` (empty if it loads).
std::string errorOf(const std::string& yaml, const std::vector<std::string>& overrides = {}) {
  try {
    parse(yaml, overrides);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

#define EXPECT_CONTAINS(s, part) \
  EXPECT_TRUE(contains(s, part)) << "message: " << (s) << "\nexpected to contain: " << (part)

}  // namespace

TEST(SceneConfig, DefaultsAreFilledAndOptionalSectionsStayAbsent) {
  auto cfg = parse(kMinimal);
  EXPECT_FALSE(cfg.has("fluid"));
  EXPECT_FALSE(cfg.has("fluid.viscosity"));  // path is in the schema, value absent
  EXPECT_TRUE(cfg.has("time"));
  EXPECT_TRUE(near(cfg.get<double>("time.dt"), 1e-3, Tol{0, 1e-15}, "time.dt"));
  EXPECT_TRUE(near(cfg.get<double>("time.end"), 1.0, Tol{0, 1e-15}, "time.end"));
  EXPECT_EQ(cfg.get<int>("time.steps"), 10);
  EXPECT_EQ(cfg.get<std::string>("name"), "demo");
  EXPECT_EQ((cfg.get<std::array<int, 3>>("mesh.cells")), (std::array<int, 3>{4, 4, 1}));
  EXPECT_EQ((cfg.get<std::array<double, 3>>("mesh.size")), (std::array<double, 3>{1, 1, 1}));
  EXPECT_EQ(cfg.size("membranes"), 0u);
  EXPECT_EQ(cfg.size("boundary"), 0u);
  EXPECT_TRUE(cfg.get<std::vector<double>>("probes").empty());
  // An empty section value names it with all its defaults.
  auto named = parse(std::string(kMinimal) + "time:\n");
  EXPECT_EQ(named.get<int>("time.steps"), 10);
}

TEST(SceneConfig, TypedAccessListsFreeMapsAndChildViews) {
  auto cfg = SceneConfig::load(MFSI_TEST_DATA_DIR "/config/good.yaml", testSchema());
  EXPECT_EQ(cfg.get<std::string>("name"), "channel");
  ASSERT_TRUE(cfg.has("fluid"));
  EXPECT_TRUE(near(cfg.get<double>("fluid.viscosity"), 1.8e-5, Tol{0, 1e-15}, "viscosity"));
  EXPECT_TRUE(near(cfg.get<double>("fluid.density"), 1000.0, Tol{0, 1e-15}, "density default"));
  EXPECT_EQ(cfg.get<std::string>("fluid.scheme"), "central");
  EXPECT_FALSE(cfg.get<bool>("fluid.verbose"));
  EXPECT_EQ((cfg.get<std::array<double, 3>>("mesh.size")), (std::array<double, 3>{2.0, 1.0, 0.1}));
  EXPECT_EQ(cfg.get<int>("mesh.cells.1"), 4);
  EXPECT_EQ(cfg.get<double>("mesh.cells.0"), 8.0);  // integers read as reals

  ASSERT_EQ(cfg.size("membranes"), 2u);
  auto m1 = cfg.child("membranes.1");
  EXPECT_EQ(m1.prefix(), "membranes.1");
  EXPECT_TRUE(near(m1.get<double>("E"), 2e6, Tol{0, 1e-15}, "E"));
  EXPECT_TRUE(near(m1.get<double>("nu"), 0.3, Tol{0, 1e-15}, "nu default inside a list item"));
  EXPECT_TRUE(near(cfg.get<double>("membranes.0.nu"), 0.45, Tol{0, 1e-15}, "nu"));

  EXPECT_EQ(cfg.keys("boundary"), (std::vector<std::string>{"inlet", "walls"}));
  EXPECT_EQ(cfg.get<std::string>("boundary.walls.type"), "wall");
  EXPECT_EQ((cfg.child("boundary").child("inlet").get<std::array<double, 3>>("velocity")),
            (std::array<double, 3>{1, 0, 0}));
  EXPECT_EQ((cfg.get<std::array<double, 3>>("boundary.walls.velocity")), (std::array<double, 3>{0, 0, 0}));
  EXPECT_EQ(cfg.get<std::vector<double>>("probes"), (std::vector<double>{0.25, 0.5, 0.75}));
  EXPECT_EQ(cfg.get<std::vector<std::string>>("tags"), (std::vector<std::string>{"smoke", "2d"}));
}

TEST(SceneConfig, WhereNamesFileLineColumnAndFullKey) {
  const std::string file = MFSI_TEST_DATA_DIR "/config/good.yaml";
  auto cfg = SceneConfig::load(file, testSchema());
  auto w = cfg.where("fluid.viscosity");
  EXPECT_EQ(w.file, file);
  EXPECT_EQ(w.line, 7);
  EXPECT_EQ(w.column, 14);
  EXPECT_EQ(w.key, "fluid.viscosity");
  // A defaulted value points at the key of the section that received it.
  auto d = cfg.where("fluid.density");
  EXPECT_EQ(d.line, 6);
  EXPECT_EQ(d.column, 1);
  // An absent value points at the closest enclosing key the scene gives (here the whole file).
  auto a = parse(kMinimal).where("fluid.viscosity");
  EXPECT_EQ(a.line, 1);
  EXPECT_EQ(a.key, "fluid.viscosity");
  // A list item points at its first line.
  EXPECT_EQ(cfg.where("membranes.1").line, 12);
  // A view names the full key; a module layer raises its own error with it.
  auto m = cfg.child("membranes.1");
  try {
    throw InputError(m.where("E"), "must exceed the fluid pressure scale");
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), file + ":12:8: key 'membranes.1.E': must exceed the fluid pressure scale");
  }
}

TEST(SceneConfig, MalformedYamlNamesLineAndColumn) {
  const std::string msg = errorOf("mesh:\n  cells: [4, 4, 1]\nfluid:\n  viscosity: [1, 2\n  scheme: upwind\n");
  EXPECT_CONTAINS(msg, "cases/test.yaml:5:");
  EXPECT_CONTAINS(msg, "YAML syntax error");
  const std::string dup = errorOf("mesh:\n  cells: [4, 4, 1]\nname: a\nname: b\n");
  EXPECT_CONTAINS(dup, "cases/test.yaml:4:1: key 'name': duplicate key");
}

TEST(SceneConfig, UnknownKeySuggestsTheClosestOne) {
  const std::string msg = errorOf("mesh:\n  cells: [4, 4, 1]\nfluid:\n  viscosty: 1e-3\n");
  EXPECT_CONTAINS(msg, "cases/test.yaml:4:3: key 'fluid.viscosty': unknown key (did you mean 'viscosity'?)");
  EXPECT_CONTAINS(msg, "allowed keys: viscosity, density, scheme, verbose");
  // From a file on disk: the path as given, line 6.
  try {
    SceneConfig::load(MFSI_TEST_DATA_DIR "/config/bad_key.yaml", testSchema());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_CONTAINS(std::string(e.what()),
                    "config/bad_key.yaml:6:3: key 'fluid.densty': unknown key (did you mean 'density'?)");
    EXPECT_EQ(e.where().line, 6);
    EXPECT_EQ(e.where().key, "fluid.densty");
  }
}

TEST(SceneConfig, WrongTypesAreReported) {
  const std::string head = "mesh:\n  cells: [4, 4, 1]\nfluid:\n";
  EXPECT_CONTAINS(errorOf(head + "  viscosity: abc\n"),
                  "cases/test.yaml:4:14: key 'fluid.viscosity': expected a real number, got 'abc'");
  EXPECT_CONTAINS(errorOf(head + "  viscosity: \"1e-3\"\n"),
                  "key 'fluid.viscosity': expected a real number, got the quoted string");
  EXPECT_CONTAINS(errorOf(head + "  viscosity: 1\n  verbose: yes\n"),
                  "cases/test.yaml:5:12: key 'fluid.verbose': expected true or false, got 'yes'");
  EXPECT_CONTAINS(errorOf(head + "  viscosity: [1]\n"), "key 'fluid.viscosity': expected a real number, got a list");
  EXPECT_CONTAINS(errorOf(head + "  viscosity:\n"),
                  "cases/test.yaml:4:3: key 'fluid.viscosity': expected a real number, got an empty value");
  EXPECT_CONTAINS(errorOf("mesh:\n  cells: [4, 4.5, 1]\n"),
                  "cases/test.yaml:2:10: key 'mesh.cells': item 1: expected an integer, got '4.5'");
  EXPECT_CONTAINS(errorOf("mesh: [1, 2]\n"), "cases/test.yaml:1:7: key 'mesh': expected a map, got a list");
  EXPECT_CONTAINS(errorOf(std::string(kMinimal) + "membranes: {E: 1}\n"),
                  "key 'membranes': expected a list, got a map");
  EXPECT_CONTAINS(errorOf(std::string(kMinimal) + "tags: []\n"),
                  "cases/test.yaml:3:7: key 'tags': needs at least 1 item(s), got 0");
  EXPECT_CONTAINS(errorOf(std::string(kMinimal) + "boundary:\n  in.let: {type: wall}\n"),
                  "cases/test.yaml:4:3: key 'boundary.in.let': names must be non-empty and contain no '.'");
}

TEST(SceneConfig, EnumValueNotAllowed) {
  const std::string msg = errorOf("mesh:\n  cells: [4, 4, 1]\nfluid:\n  viscosity: 1\n  scheme: upwnd\n");
  EXPECT_CONTAINS(msg,
                  "cases/test.yaml:5:11: key 'fluid.scheme': 'upwnd' is not allowed (did you mean 'upwind'?); "
                  "choices: upwind, central, quick");
  const std::string bc = errorOf(std::string(kMinimal) + "boundary:\n  inlet:\n    type: wal\n");
  EXPECT_CONTAINS(bc, "cases/test.yaml:5:11: key 'boundary.inlet.type': 'wal' is not allowed (did you mean 'wall'?)");
}

TEST(SceneConfig, MissingRequiredKey) {
  EXPECT_CONTAINS(errorOf("name: x\n"),
                  "cases/test.yaml:1:1: key 'mesh': missing required key (a map: structured box mesh)");
  EXPECT_CONTAINS(
      errorOf("mesh:\n  cells: [4, 4, 1]\n\nfluid:\n  density: 1.2\n"),
      "cases/test.yaml:4:1: key 'fluid.viscosity': missing required key (a real number: dynamic viscosity)");
  EXPECT_CONTAINS(errorOf(std::string(kMinimal) + "membranes:\n  - E: 1\n  - nu: 0.2\n"),
                  "cases/test.yaml:5:5: key 'membranes.1.E': missing required key");
  EXPECT_CONTAINS(errorOf(""), "cases/test.yaml:1:1: key 'mesh': missing required key");
}

TEST(SceneConfig, OutOfBoundsNanAndInf) {
  const std::string head = "mesh:\n  cells: [4, 4, 1]\nfluid:\n";
  EXPECT_CONTAINS(errorOf(head + "  viscosity: -1\n"),
                  "cases/test.yaml:4:14: key 'fluid.viscosity': value -1 is out of range: must be > 0");
  EXPECT_CONTAINS(errorOf(head + "  viscosity: 0\n"), "must be > 0");
  EXPECT_TRUE(errorOf(head + "  viscosity: 1e-300\n").empty());
  EXPECT_CONTAINS(errorOf(std::string(kMinimal) + "membranes:\n  - E: 1\n    nu: 0.5\n"),
                  "cases/test.yaml:5:9: key 'membranes.0.nu': value 0.5 is out of range: must be >= 0 and < 0.5");
  EXPECT_TRUE(errorOf(std::string(kMinimal) + "membranes:\n  - E: 1\n    nu: 0\n").empty());
  EXPECT_CONTAINS(errorOf("mesh:\n  cells: [4, 0, 1]\n"),
                  "key 'mesh.cells': item 1: value 0 is out of range: must be >= 1");
  for (const char* bad : {".nan", ".inf", "-.inf", "nan", "NaN", "inf", "1e999"})
    EXPECT_CONTAINS(
        errorOf(head + "  viscosity: " + bad + "\n"),
        "cases/test.yaml:4:14: key 'fluid.viscosity': expected a finite real number, got '" + std::string(bad) + "'");
  EXPECT_CONTAINS(errorOf("mesh:\n  cells: [4, 4, 99999999999]\n"), "integer '99999999999' is too large");
}

TEST(SceneConfig, WrongVectorLength) {
  EXPECT_CONTAINS(errorOf("mesh:\n  cells: [4, 4]\n"),
                  "cases/test.yaml:2:10: key 'mesh.cells': expected a list of 3 integers, got 2 items");
  EXPECT_CONTAINS(errorOf("mesh:\n  cells: 4\n"), "key 'mesh.cells': expected a list of 3 integers, got '4'");
}

TEST(SceneConfig, MissingFile) {
  try {
    SceneConfig::load("cases/does_not_exist.yaml", testSchema());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_CONTAINS(std::string(e.what()), "cannot open scene file 'cases/does_not_exist.yaml'");
  }
}

TEST(SceneConfig, OverridesSetCreateAndAppend) {
  auto cfg = parse(std::string(kMinimal) + "membranes:\n  - E: 1\n",
                   {"mesh.cells=[8,8,2]", "fluid.viscosity=2e-3", "membranes.0.nu=0.25", "membranes.1={E: 3}",
                    "boundary.inlet.type=inlet", "mesh.size.2=0.5", "name='1.5'"});
  EXPECT_EQ((cfg.get<std::array<int, 3>>("mesh.cells")), (std::array<int, 3>{8, 8, 2}));
  ASSERT_TRUE(cfg.has("fluid"));  // created by the override, with its defaults
  EXPECT_TRUE(near(cfg.get<double>("fluid.viscosity"), 2e-3, Tol{0, 1e-15}, "viscosity"));
  EXPECT_TRUE(near(cfg.get<double>("fluid.density"), 1000.0, Tol{0, 1e-15}, "density"));
  ASSERT_EQ(cfg.size("membranes"), 2u);
  EXPECT_TRUE(near(cfg.get<double>("membranes.0.E"), 1.0, Tol{0, 1e-15}, "E kept"));
  EXPECT_TRUE(near(cfg.get<double>("membranes.0.nu"), 0.25, Tol{0, 1e-15}, "nu set"));
  EXPECT_TRUE(near(cfg.get<double>("membranes.1.E"), 3.0, Tol{0, 1e-15}, "appended"));
  EXPECT_EQ(cfg.get<std::string>("boundary.inlet.type"), "inlet");
  EXPECT_EQ((cfg.get<std::array<double, 3>>("mesh.size")), (std::array<double, 3>{1, 1, 0.5}));
  EXPECT_EQ(cfg.get<std::string>("name"), "1.5");
  EXPECT_EQ(cfg.where("fluid.viscosity").file, "--set fluid.viscosity=2e-3");
  // The later override wins.
  EXPECT_EQ(parse(kMinimal, {"time.steps=3", "time.steps=7"}).get<int>("time.steps"), 7);
}

TEST(SceneConfig, OverrideErrors) {
  EXPECT_CONTAINS(
      errorOf(kMinimal, {"fluid.viscosty=2"}),
      "--set fluid.viscosty=2: key 'fluid.viscosty': unknown key (did you mean 'viscosity'?); allowed keys:");
  EXPECT_CONTAINS(errorOf(kMinimal, {"fluid.viscosity=abc"}),
                  "--set fluid.viscosity=abc: key 'fluid.viscosity': expected a real number, got 'abc'");
  EXPECT_CONTAINS(
      errorOf(kMinimal, {"membranes.3.E=1"}),
      "--set membranes.3.E=1: key 'membranes.3': item 3 does not exist: 'membranes' has 0 item(s) (use index 0");
  EXPECT_CONTAINS(errorOf(kMinimal, {"fluid.viscosity.x=1"}), "'fluid.viscosity' is a real number, it has no sub-keys");
  EXPECT_CONTAINS(errorOf(kMinimal, {"membranes.first.E=1"}), "'membranes' is a list, 'first' is not an item index");
  EXPECT_CONTAINS(errorOf(kMinimal, {"fluid.viscosity"}), "--set fluid.viscosity: expected --set key.path=value");
  EXPECT_CONTAINS(errorOf(kMinimal, {"mesh.cells=[1, 2"}), "--set mesh.cells=[1, 2: YAML syntax error");
  // The section created by --set misses its required key: the error names the override.
  EXPECT_CONTAINS(errorOf(kMinimal, {"fluid.density=2"}),
                  "--set fluid.density=2: key 'fluid.viscosity': missing required key");
}

TEST(SceneConfig, ResolvedYamlWritesPathsAbsolute) {
  // A path relative to the scene's folder is written absolute (a run's copy of its scene, in its
  // output folder, names the same file); an absolute one and a plain string stay as they are.
  const Schema schema = Schema::map("scene")
                            .key("mesh", Schema::path("a file"))
                            .key("other", Schema::path("another"))
                            .key("name", Schema::string("a name"));
  const auto cfg = SceneConfig::fromString("mesh: meshes/a.msh\nother: /data/b.msh\nname: meshes/c\n",
                                           "/some/where/scene.yaml", schema);
  const std::string yaml = cfg.resolvedYaml(false);
  EXPECT_CONTAINS(yaml, "mesh: /some/where/meshes/a.msh");
  EXPECT_CONTAINS(yaml, "other: /data/b.msh");
  EXPECT_CONTAINS(yaml, "name: meshes/c");
  // A scene named relative to the working directory: absolute against it.
  const auto rel = SceneConfig::fromString("mesh: ../m.msh\nother: x\nname: n\n", "cases/s.yaml", schema);
  EXPECT_CONTAINS(rel.resolvedYaml(false),
                  "mesh: " + (std::filesystem::current_path() / "m.msh").lexically_normal().string());
}

TEST(SceneConfig, ResolvedYamlRoundTrips) {
  auto cfg = SceneConfig::load(MFSI_TEST_DATA_DIR "/config/good.yaml", testSchema(), {"name='it''s: \"quoted\"'"});
  const std::string commented = cfg.resolvedYaml();
  EXPECT_CONTAINS(commented, "density: 1000  # default");
  EXPECT_CONTAINS(commented, "cells: [8, 4, 1]");
  const std::string plain = cfg.resolvedYaml(false);
  EXPECT_FALSE(contains(plain, "# default"));
  auto back = SceneConfig::fromString(commented, "resolved.yaml", testSchema());
  EXPECT_EQ(back.resolvedYaml(false), plain);
  EXPECT_EQ(back.get<std::string>("name"), "it's: \"quoted\"");
  EXPECT_EQ(back.get<std::string>("boundary.inlet.type"), "inlet");
  EXPECT_EQ(back.size("membranes"), 2u);
  EXPECT_TRUE(near(back.get<double>("membranes.1.nu"), 0.3, Tol{0, 1e-15}, "nu"));
  // An absent optional section stays absent in the resolved scene.
  const std::string minimal = parse(kMinimal).resolvedYaml();
  EXPECT_FALSE(contains(minimal, "fluid"));
  EXPECT_CONTAINS(minimal, "boundary: {}  # default");
  EXPECT_EQ(SceneConfig::fromString(minimal, "resolved.yaml", testSchema()).resolvedYaml(false),
            parse(kMinimal).resolvedYaml(false));
  // A view resolves its own sub-tree.
  EXPECT_EQ(cfg.child("membranes.0").resolvedYaml(false), "E: 1e6\nnu: 0.45\n");
}

TEST(SceneConfig, DocumentationListsTypesDefaultsUnitsAndDocs) {
  const std::string doc = mfsi::describeSchema(testSchema());
  EXPECT_CONTAINS(doc, "viscosity:");
  EXPECT_CONTAINS(doc, "(a real number, required, > 0, units Pa s)  dynamic viscosity");
  EXPECT_CONTAINS(doc, "(a real number, default 0.001, > 0, units s)  time step");
  EXPECT_CONTAINS(doc, "(a map, optional section)  incompressible fluid");
  EXPECT_CONTAINS(doc, "one of upwind, central, quick, default 'upwind'");
  EXPECT_CONTAINS(doc, "<name>:");
  EXPECT_CONTAINS(doc, "(a real number, default 0.3, >= 0 and < 0.5, units -)  Poisson ratio");
}

TEST(SceneConfig, SchemaBugsAndProgrammerErrorsAreLogicErrors) {
  EXPECT_THROW(Schema::map("m").key("x", Schema::real("x", "m"), Presence::Optional), std::logic_error);
  EXPECT_THROW(Schema::map("m").key("x", Schema::real("x", "m").greaterThan(0), Default(-1.0)), std::logic_error);
  EXPECT_THROW(Schema::map("m").key("x", Schema::intVector(3, "n"), Default(std::array<int, 2>{1, 2})),
               std::logic_error);
  EXPECT_THROW(Schema::map("m").key("x", Schema::string("a")).key("x", Schema::string("b")), std::logic_error);
  EXPECT_THROW(Schema::string("s").atLeast(0), std::logic_error);
  auto cfg = parse(kMinimal);
  EXPECT_THROW(cfg.get<double>("time.dtt"), std::logic_error);         // not in the schema
  EXPECT_THROW(cfg.has("fluidd"), std::logic_error);                   // typos never read as "absent"
  EXPECT_THROW(cfg.get<int>("time.dt"), std::logic_error);             // wrong type
  EXPECT_THROW(cfg.get<double>("fluid.viscosity"), std::logic_error);  // absent section
  EXPECT_THROW((cfg.get<std::array<int, 2>>("mesh.cells")), std::logic_error);
}
