// summary.json is valid UTF-8 JSON whatever bytes its strings hold (issue 14): a scene file named
// in Latin-1, a key with a stray byte echoed in the error message. Well-formed UTF-8 is kept as it
// is, each byte outside a well-formed sequence becomes \ufffd, control characters \u00XX (or \n,
// \r, \t). Checked on the escaping itself, and on the summaries `mfsi run` writes for bad scenes.
#include "core/RunLog.hpp"
#include "support/FreshDir.hpp"
#include "support/Spawn.hpp"
#include "support/StrictJson.hpp"
#include "support/TextFiles.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

namespace {

namespace fs = std::filesystem;

const std::string kBad = "\\ufffd";

}  // namespace

TEST(JsonEscape, KeepsWellFormedUtf8AndEscapesQuotesBackslashesAndControls) {
  EXPECT_EQ(mfsi::jsonEscape("plain text 1.5"), "plain text 1.5");
  EXPECT_EQ(mfsi::jsonEscape("a \"b\" c\\d"), "a \\\"b\\\" c\\\\d");
  EXPECT_EQ(mfsi::jsonEscape("l1\nl2\r\tx"), "l1\\nl2\\r\\tx");
  EXPECT_EQ(mfsi::jsonEscape(std::string("\x01\x1f\x7f", 3) + std::string(1, '\0')), "\\u0001\\u001f\x7f\\u0000");
  // 2, 3 and 4 bytes: é, €, U+FFFD itself, 😀, and the ends of the range (U+0080, U+10FFFF).
  for (const char* s :
       {"caf\xc3\xa9", "\xe2\x82\xac", "\xef\xbf\xbd", "\xf0\x9f\x98\x80", "\xc2\x80", "\xf4\x8f\xbf\xbf"})
    EXPECT_EQ(mfsi::jsonEscape(s), s);
}

TEST(JsonEscape, ReplacesEachByteOutsideAWellFormedSequence) {
  EXPECT_EQ(mfsi::jsonEscape("caf\xe9"), "caf" + kBad);                                 // Latin-1 é
  EXPECT_EQ(mfsi::jsonEscape("\xff\xfe"), kBad + kBad);                                 // never in UTF-8
  EXPECT_EQ(mfsi::jsonEscape("\x80x"), kBad + "x");                                     // a lone continuation
  EXPECT_EQ(mfsi::jsonEscape("a\xc3"), "a" + kBad);                                     // cut off at the end
  EXPECT_EQ(mfsi::jsonEscape("\xe2\x82x"), kBad + kBad + "x");                          // cut off in the middle
  EXPECT_EQ(mfsi::jsonEscape("\xc0\xaf"), kBad + kBad);                                 // overlong '/'
  EXPECT_EQ(mfsi::jsonEscape("\xe0\x80\xaf"), kBad + kBad + kBad);                      // overlong, 3 bytes
  EXPECT_EQ(mfsi::jsonEscape("\xed\xa0\x80"), kBad + kBad + kBad);                      // a UTF-16 surrogate
  EXPECT_EQ(mfsi::jsonEscape("\xf4\x90\x80\x80"), kBad + kBad + kBad + kBad);           // above U+10FFFF
  EXPECT_EQ(mfsi::jsonEscape("\xc3\xa9\xa9\xc3\xa9"), "\xc3\xa9" + kBad + "\xc3\xa9");  // é, stray, é
}

TEST(JsonEscape, ASummaryOfAnyBytesIsStrictJson) {
  mfsi::RunSummary s;
  s.scene = "sc\xe8ne\xff";
  s.status = "error";
  s.error = "bad \"key\" 'n\xffu'\n\tat line 3\x01\x1b[31m\\";
  s.backend = "Open\xc3MP";
  s.wallSeconds = std::numeric_limits<double>::quiet_NaN();
  s.simTime = -std::numeric_limits<double>::infinity();
  s.timers["phase\xa0"] = 1.5e-300;
  s.metrics["m\x7f\x02"] = -0.0;
  const std::string json = mfsi::toJson(s);
  EXPECT_EQ(mfsi::test::strictJsonError(json), "") << json;
  EXPECT_NE(json.find("\"wall_s\": null"), std::string::npos) << json;
}

TEST(JsonEscape, TheStrictCheckRefusesWhatIsNotJson) {
  // The check the tests rely on is itself strict.
  for (const std::string bad : {"{\"a\": NaN}", "{\"a\": \"\xff\"}", "{\"a\": \"x\ny\"}", "{\"a\": 01}",
                                "{\"a\": \"\\ud800\"}", "{\"a\": 1,}", "{\"a\": \"\\x\"}", "{} {}", "\"\xc0\xaf\""})
    EXPECT_NE(mfsi::test::strictJsonError(bad), "") << bad;
  EXPECT_EQ(mfsi::test::strictJsonError("{\"a\": [1, -2.5e+3, true, null, \"\\u00e9\\ud83d\\ude00\"]}"), "");
}

TEST(SummaryJson, ABadSceneWithInvalidBytesInItsNameAndKeysGivesStrictJson) {
  const std::string dir = mfsi::test::freshDir("summary_json");
  // A file name in Latin-1 (the scene's name in the summary, and in the message), a key with a
  // stray byte (in the message: unknown key, did you mean 'nu'?).
  const std::string scene = dir + "/sc\xe8ne\xff.yaml";
  std::ofstream(scene) << "time: {endTime: 1, dt: 0.5}\n"
                          "mesh:\n"
                          "  blocks:\n"
                          "    - {min: [0, 0, 0], max: [1, 1, 1], cells: [2, 2, 2],\n"
                          "       patches: {xmin: w, xmax: w, ymin: w, ymax: w, zmin: w, zmax: w}}\n"
                          "  patchTypes: {w: wall}\n"
                          "fluid:\n"
                          "  n\xffu: 0.01\n";
  const auto r = mfsi::test::run({MFSI_EXE, "run", scene, "--out", dir + "/out"});
  EXPECT_EQ(r.code, 2) << r.output;
  const std::string json = mfsi::test::readFile(dir + "/out/summary.json");
  EXPECT_EQ(mfsi::test::strictJsonError(json), "") << json;
  EXPECT_NE(json.find("\"status\": \"error\""), std::string::npos) << json;
  EXPECT_NE(json.find("'fluid.n" + kBad + "u'"), std::string::npos) << json;
  EXPECT_NE(json.find("sc" + kBad + "ne" + kBad), std::string::npos) << json;
}

TEST(SummaryJson, ASceneNameWithInvalidBytesAndControlsGivesStrictJson) {
  const std::string dir = mfsi::test::freshDir("summary_json_name");
  // The scene loads (its name is the summary's scene), then fails: a step needs a time step.
  const std::string scene = dir + "/scene.yaml";
  std::ofstream(scene) << "name: \"caf\xe9 \\t \\x01 \\\" done\"\n"
                          "time: {endTime: 1}\n"
                          "mesh:\n"
                          "  blocks:\n"
                          "    - {min: [0, 0, 0], max: [1, 1, 1], cells: [2, 2, 2],\n"
                          "       patches: {xmin: w, xmax: w, ymin: w, ymax: w, zmin: w, zmax: w}}\n"
                          "  patchTypes: {w: wall}\n";
  const auto r = mfsi::test::run({MFSI_EXE, "run", scene, "--out", dir + "/out"});
  EXPECT_EQ(r.code, 2) << r.output;
  const std::string json = mfsi::test::readFile(dir + "/out/summary.json");
  EXPECT_EQ(mfsi::test::strictJsonError(json), "") << json;
  EXPECT_NE(json.find("\"scene\": \"caf" + kBad + " \\t \\u0001 \\\" done\""), std::string::npos) << json;
  EXPECT_NE(json.find("time.dt"), std::string::npos) << json;
}
