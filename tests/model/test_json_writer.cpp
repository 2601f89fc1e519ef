// The one JSON writer of the tools' --json and the services' summaries (common/json_writer.hpp).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>

#include "common/json_writer.hpp"

using mft::config::JsonWriter;
using mft::config::kRoundTrip;

TEST(JsonWriter, NestsObjectsAndArraysWithCommasInTheRightPlaces) {
  JsonWriter w;
  w.beginObject();
  w.field("name", "demo").field("count", 3).field("ok", true);
  w.key("empty").beginArray().endArray();
  w.key("list").beginArray().value(1).beginObject().field("a", -2).endObject().beginArray().value(false).endArray().endArray();
  w.key("inner").beginObject().key("x").null().endObject();
  w.endObject();
  EXPECT_EQ(w.str(),
            R"({"name": "demo", "count": 3, "ok": true, "empty": [], "list": [1, {"a": -2}, [false]], "inner": {"x": null}})");
}

TEST(JsonWriter, EscapesQuotesBackslashesAndEveryControlCharacter) {
  JsonWriter w;
  w.beginObject().field("s", std::string("a\"b\\c\n\t\r\b\f\x01\x1f\x7f") + "\xc3\xa9").endObject();
  EXPECT_EQ(w.str(), R"({"s": "a\"b\\c\n\t\r\b\f\u0001\u001f\u007f)" "\xc3\xa9\"}");
  JsonWriter k;
  k.beginObject().field("k\"ey", 1).endObject();
  EXPECT_EQ(k.str(), R"({"k\"ey": 1})");
}

TEST(JsonWriter, NumbersAreNullWhenNotFiniteAndRoundTripByDefault) {
  JsonWriter w;
  w.beginArray()
      .value(std::nan(""))
      .value(std::numeric_limits<double>::infinity())
      .value(-std::numeric_limits<double>::infinity())
      .value(0.1)
      .value(1.0 / 3.0)
      .value(1e-300)
      .value(2.0)
      .value(0.123456789012, 3)
      .fixed(2.0 / 3.0, 3)
      .fixed(std::nan(""), 3)
      .value(std::uint64_t{18446744073709551615ULL})
      .value(std::int64_t{-9007199254740993LL})
      .endArray();
  EXPECT_EQ(w.str(), "[null, null, null, 0.1, 0.3333333333333333, 1e-300, 2, 0.123, 0.667, null, "
                     "18446744073709551615, -9007199254740993]");
  for (const double v : {0.1, 1.0 / 3.0, 1e-300, 123456.789, -2.5e17, 5e-324})
    EXPECT_EQ(std::strtod(mft::config::jsonNumber(v, kRoundTrip).c_str(), nullptr), v) << v;
}

TEST(JsonWriter, RefusesMisuseInsteadOfWritingBadJson) {
  JsonWriter a;
  a.beginObject();
  EXPECT_THROW(a.value(1), std::logic_error);  // a value without a key
  EXPECT_THROW(a.str(), std::logic_error);     // still open
  JsonWriter b;
  b.beginArray();
  EXPECT_THROW(b.key("x"), std::logic_error);  // a key in an array
  EXPECT_THROW(b.endObject(), std::logic_error);
  JsonWriter c;
  c.value(1);
  EXPECT_THROW(c.value(2), std::logic_error);  // two top-level values
}

// Python's json module reads back exactly what was written: every byte of an awkward string and every number.
TEST(JsonWriter, PythonsJsonModuleReadsItBackExactly) {
  std::string nasty;
  for (int c = 1; c < 0x80; ++c) nasty += static_cast<char>(c);
  nasty += "\xe2\x82\xac";  // UTF-8 passes through
  JsonWriter w;
  w.beginObject().field("s", nasty).key("n").beginArray().value(0.1).value(1.0 / 3.0).value(-1e-310).value(6.02214076e23);
  w.value(std::nan("")).endArray().key("deep").beginObject().key("a").beginArray().beginArray().endArray().endArray();
  w.endObject().endObject();
  const auto dir = std::filesystem::temp_directory_path();
  const auto json = dir / ("mft-json-writer-" + std::to_string(::getpid()) + ".json");
  const auto out = dir / ("mft-json-writer-" + std::to_string(::getpid()) + ".txt");
  std::ofstream(json) << w.str();
  const std::string cmd = "/usr/bin/python3 -c \"import json,sys; d=json.load(open(sys.argv[1])); "
                          "print(d['s'].encode('utf-8').hex()); print(' '.join(repr(x) for x in d['n'])); "
                          "print(d['deep'])\" " +
                          json.string() + " > " + out.string();
  ASSERT_EQ(std::system(cmd.c_str()), 0) << "python3 could not parse: " << w.str();
  std::ifstream in(out);
  std::string hex, numbers, deep;
  std::getline(in, hex);
  std::getline(in, numbers);
  std::getline(in, deep);
  std::string expected_hex;
  char buf[3];
  for (const unsigned char c : nasty) {
    std::snprintf(buf, sizeof buf, "%02x", c);
    expected_hex += buf;
  }
  EXPECT_EQ(hex, expected_hex);
  EXPECT_EQ(numbers, "0.1 0.3333333333333333 -1e-310 6.02214076e+23 None");
  EXPECT_EQ(deep, "{'a': [[]]}");
  std::filesystem::remove(json);
  std::filesystem::remove(out);
}
