// Bad input of the shared JSON reader (railproof/offline/json_reader.hpp), which every loader
// of the offline tools reads through: the file (missing, a directory, not a regular file, too
// large), the text (not UTF-8, not JSON, a key twice in one object, nested too deep), the
// messages (one line, the input's text quoted and cut) and the typed reads that check a range
// before a value is converted. Each case asserts the whole message.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "railproof/offline/json_reader.hpp"
#include "railproof/offline/line.hpp"
#include "railproof/offline/train_type.hpp"

namespace railproof::offline {
namespace {

namespace fs = std::filesystem;

// The message of the InputError `run` throws ("" if none).
template <typename F>
std::string ErrorOf(F run) {
  try {
    run();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string ParseError(const std::string& text) {
  return ErrorOf([&] { (void)JsonDocument(text, "in.json"); });
}

// A fresh scratch folder for one test.
fs::path Scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("railproof_json_reader_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(JsonReader, ADuplicateKeyIsRefusedWhereverItStands) {
  EXPECT_EQ(ParseError(R"({"a": 1, "b": 2, "a": 3})"), "in.json: (top level): duplicate key 'a'");
  EXPECT_EQ(ParseError(R"({"x": {"k": {"b": 1, "b": 1}}})"), "in.json: x.k: duplicate key 'b'");
  EXPECT_EQ(ParseError(R"({"x": [{"k": 1}, 2, [3], {"k": 1, "k": 2}]})"), "in.json: x[3]: duplicate key 'k'");
  // the same key in two objects is no duplicate
  EXPECT_EQ(ParseError(R"({"x": [{"k": 1}, {"k": 2}], "k": 3})"), "");
}

TEST(JsonReader, NestingIsBounded) {
  const std::string ok = std::string(64, '[') + std::string(64, ']');
  EXPECT_EQ(ParseError(ok), "");
  std::string path;
  for (int i = 0; i < 64; ++i) {
    path += "[0]";
  }
  const std::string deep = std::string(65, '[') + std::string(65, ']');
  EXPECT_EQ(ParseError(deep), "in.json: " + path + ": nested deeper than 64 levels");
  // a megabyte of brackets is refused at the 65th, without building anything
  EXPECT_EQ(ParseError(std::string(1 << 20, '[')), "in.json: " + path + ": nested deeper than 64 levels");
}

TEST(JsonReader, TextThatIsNotUtf8OrNotJsonIsNamed) {
  EXPECT_EQ(ParseError("{\"name\": \"\xff\"}"), "in.json: not UTF-8 text: invalid UTF-8 byte at index 10: 0xFF");
  EXPECT_EQ(ParseError("{\"a\" 1}"),
            "in.json: invalid JSON: parse error at line 1, column 6: syntax error while parsing object separator - "
            "unexpected number literal; expected ':'");
  EXPECT_EQ(ParseError("{\"a\": NaN}"),
            "in.json: invalid JSON: parse error at line 1, column 7: syntax error while parsing value - invalid "
            "literal; last read: '\"a\": N'");
  EXPECT_EQ(ParseError("{\"a\": 1e400}"),
            "in.json: invalid JSON: number overflow parsing '1e400'");
  // the parser's "last read" ends inside a character: the message stays UTF-8
  EXPECT_EQ(ParseError("[1,\xc3\xa9]"),
            "in.json: invalid JSON: parse error at line 1, column 4: syntax error while parsing value - invalid "
            "literal; last read: '1,\xef\xbf\xbd'");
  // a long bad token is cut, the message stays short
  const std::string long_token = "[\"" + std::string(100000, 'x');
  EXPECT_LT(ParseError(long_token).size(), 300U);
}

TEST(JsonReader, MessagesAreOneLineWithTheInputsTextQuotedAndCut) {
  const std::string text = R"({"schema": "s", "a\nb": 1, "c": {"id": "one\ttwo"}})";
  const std::string file = "in.json";  // outlives the document
  const JsonDocument doc(text, file);
  EXPECT_EQ(ErrorOf([&] { doc.AllowOnly({"schema", "c"}); }), "in.json: (top level): unknown key 'a\\nb'");
  const JsonNode c = doc.Key("c").Labelled(doc.Key("c").Key("id").String());
  EXPECT_EQ(ErrorOf([&] { (void)c.Key("x"); }), "in.json: c (one\\ttwo): missing key 'x'");
  const std::string long_key = std::string(100, 'k');
  EXPECT_EQ(ErrorOf([&] { (void)doc.Key(long_key); }), "in.json: (top level): missing key '" + std::string(64, 'k') + "...'");
  EXPECT_EQ(ErrorOf([&] { (void)JsonDocument(R"({"schema": "x\u0001"})", "in.json", "railproof/line-json/1"); }),
            "in.json: schema: unsupported schema 'x\\x01', expected 'railproof/line-json/1'");
}

TEST(JsonReader, RangesAreCheckedBeforeAValueIsConverted) {
  const std::string file = "in.json";  // outlives the document
  const JsonDocument doc(R"({"i": 301, "big": 1e300, "neg": -1, "m": 12.3456, "pair": [5, 2], "one": [1], "f": 0})",
                         file);
  EXPECT_EQ(ErrorOf([&] { (void)doc.Key("i").IntIn(1, 300, "km/h"); }), "in.json: i: value 301 km/h is outside [1, 300]");
  EXPECT_EQ(ErrorOf([&] { (void)doc.Key("big").ScaledIn({0.0, 1e7}, 1000.0, "m"); }),
            "in.json: big: value 1e+300 m is outside [0, 1e+07]");
  EXPECT_EQ(ErrorOf([&] { (void)doc.Key("f").NumberIn({0.0, 5.0, true}); }), "in.json: f: value 0 is outside (0, 5]");
  EXPECT_EQ(ErrorOf([&] { (void)doc.Key("neg").NumberIn({0.0, 1.0}); }), "in.json: neg: value -1 is outside [0, 1]");
  EXPECT_EQ(doc.Key("m").ScaledIn({0.0, 1e7}, 1000.0, "m"), 12346);
  EXPECT_EQ(ErrorOf([&] { (void)doc.Key("pair").IntPairIn(0, 10, "ms"); }),
            "in.json: pair: min 5 ms is greater than max 2 ms");
  EXPECT_EQ(ErrorOf([&] { (void)doc.Key("one").IntPairIn(0, 10, "ms"); }),
            "in.json: one: expected [min, max], got 1 element(s)");
  // a range whose conversion could leave the integers is the loader's mistake, not the input's
  EXPECT_THROW((void)doc.Key("m").ScaledIn({0.0, 1e300}, 1000.0), std::logic_error);
}

TEST(JsonReader, AFileThatCannotBeReadIsNamedWithTheReason) {
  const fs::path dir = Scratch("files");
  EXPECT_EQ(ErrorOf([&] { (void)ReadInputFile(dir / "none.json", "line file"); }),
            (dir / "none.json").string() + ": cannot read line file: No such file or directory");
  EXPECT_EQ(ErrorOf([&] { (void)ReadInputFile(dir, "scenario file"); }),
            dir.string() + ": cannot read scenario file: Is a directory");
  EXPECT_EQ(ErrorOf([&] { (void)ReadInputFile("/dev/null", ""); }), "/dev/null: cannot read file: not a regular file");
  {
    std::ofstream(dir / "blocker") << "x";
  }
  EXPECT_EQ(ErrorOf([&] { (void)ReadInputFile(dir / "blocker" / "x.json", "train type"); }),
            (dir / "blocker" / "x.json").string() + ": cannot read train type: Not a directory");
  // the size is checked before anything is read (a sparse file of the limit plus one byte)
  {
    std::ofstream(dir / "big.json") << "";
  }
  fs::resize_file(dir / "big.json", kMaxInputBytes + 1);
  EXPECT_EQ(ErrorOf([&] { (void)ReadInputFile(dir / "big.json", "line file"); }),
            (dir / "big.json").string() + ": cannot read line file: larger than the input limit of 16777216 bytes");
  fs::resize_file(dir / "big.json", 3);
  EXPECT_EQ(ReadInputFile(dir / "big.json", "line file"), std::string(3, '\0'));
  fs::remove_all(dir);
}

TEST(JsonReader, EveryLoaderReadsThroughIt) {
  const fs::path dir = Scratch("loaders");
  EXPECT_EQ(ErrorOf([&] { (void)LoadLine(dir); }), dir.string() + ": cannot read line file: Is a directory");
  {
    std::ofstream(dir / "t.json") << R"({"schema": "railproof/train-json/1", "name": "a", "name": "b"})";
  }
  EXPECT_EQ(ErrorOf([&] { (void)LoadTrainType(dir / "t.json"); }),
            (dir / "t.json").string() + ": (top level): duplicate key 'name'");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace railproof::offline
