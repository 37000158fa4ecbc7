#include "pixelgym/engine/xml_depth.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <tinyxml.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

namespace pixelgym::engine {
namespace {

// How deep the tree TinyXML built nests elements; a parse that stops at an error keeps the
// elements it entered, so this is also how deep its recursion went.
std::size_t tree_depth(const TiXmlNode& node) {
  std::size_t deepest = 0;
  for (const TiXmlNode* child = node.FirstChild(); child != nullptr; child = child->NextSibling())
    deepest = std::max(deepest, tree_depth(*child));
  return deepest + (node.ToElement() != nullptr ? 1 : 0);
}

struct Parsed {
  std::size_t depth;
  bool error;
};

Parsed tinyxml_parse(const std::string& text) {
  TiXmlDocument document;
  document.Parse((text + std::string(kTinyXmlPadding, '\0')).c_str());
  return {tree_depth(document), document.Error()};
}

std::string repeat(const std::string& piece, int times) {
  std::string text;
  for (int i = 0; i < times; ++i) text += piece;
  return text;
}

// `open`, 150 times, inside a robot: TinyXML nests 151 deep however the text around hides it from
// a simpler reader.
std::string nest(const std::string& before, const std::string& after = "") {
  return "<robot name=\"r\"><link name=\"a\"/>" + before + repeat("<x>", 150) + after +
         repeat("</x>", 150) + "</robot>";
}

TEST(XmlDepthTest, CountsAsTinyXmlNestsWhatASimplerReaderSkips) {
  struct Case {
    const char* why;
    std::string text;
    std::size_t depth = 151;
  };
  const std::vector<Case> cases = {
      // '<' then a byte that starts no name: an unknown node, to the first '>' (quotes or not).
      {"unknown node with a quote", nest("<1 \">", "\">")},
      {"unknown node '< a'", nest("< a \">", "\">")},
      {"'<!' node", nest("<!DOCTYPE \">", "\">")},
      {"'<?' that is not <?xml", nest("<?pi \">", "\">")},
      // A character reference runs to the first ';' if digits precede it: "&#<!--#1;".
      {"character reference over a comment opener", nest("&#<!--#1;", "-->")},
      {"hex reference over a CDATA opener", nest("&#x<![CDATA[x1;", "]]>")},
      // After a UTF-8 declaration a lead byte swallows the two bytes after it, quote included.
      // (<y> holds the nest: 152 deep.)
      {"UTF-8 lead byte hiding a closing quote",
       "<?xml version=\"1.0\" encoding=\"UTF-8\"?>" + nest("<y z=\"\xe0\" \">", "\"/>"), 152},
      {"UTF-8 chosen by a declaration without encoding",
       "<?xml version=\"1.0\"?>" + nest("<y z=\"\xe0\" \">", "\"/>"), 152},
      {"UTF-8 chosen by a byte order mark", "\xef\xbb\xbf" + nest("<y z=\"\xe0\" \">", "\"/>"),
       152},
  };
  for (const Case& c : cases) {
    const Parsed parsed = tinyxml_parse(c.text);
    EXPECT_EQ(parsed.depth, c.depth) << c.why << ": the case no longer tests what it says";
    EXPECT_EQ(tinyxml_element_depth(c.text, 1000), c.depth) << c.why;
    EXPECT_EQ(tinyxml_element_depth(c.text, 100), 101U) << c.why << ": stops past the limit";
  }
}

TEST(XmlDepthTest, WhatTinyXmlDoesNotNestIsNotCounted) {
  // Comments, CDATA, quoted values, self-closing tags, a legacy encoding's bytes as themselves.
  const std::vector<std::string> flat = {
      "<robot><!-- <a><a><a> --><link name=\">\"/><![CDATA[<b><b>]]><?pi <c>?><a/></robot>",
      "<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?><robot><y z=\"\xe0\"/><a/></robot>",
      "<robot><y z=\"&lt;a&gt;&lt;a&gt;\" w='\"<a>'/>text &amp; &#60; more</robot>",
  };
  for (const std::string& text : flat) {
    EXPECT_EQ(tinyxml_parse(text).depth, 2U) << text;
    EXPECT_EQ(tinyxml_element_depth(text, 100), 2U) << text;
  }
  EXPECT_EQ(tinyxml_element_depth("", 100), 0U);
  EXPECT_EQ(tinyxml_element_depth("just text", 100), 0U);
}

// Random texts made of the pieces TinyXML treats specially, parsed by TinyXML and walked: the walk
// never counts less, and exactly as deep when TinyXML parsed without an error.
TEST(XmlDepthTest, AgreesWithTinyXmlOnRandomTexts) {
  const std::vector<std::string> pieces = {"<a>",
                                           "</a>",
                                           "<b c=\"1\">",
                                           "</b>",
                                           "<a/>",
                                           "<d ",
                                           ">",
                                           "/>",
                                           "\"",
                                           "'",
                                           "=",
                                           " ",
                                           "\n",
                                           "x",
                                           "1",
                                           "<",
                                           "</",
                                           "<!--",
                                           "-->",
                                           "<![CDATA[",
                                           "]]>",
                                           "<?xml",
                                           "?>",
                                           "<?xml version=\"1.0\" encoding=\"UTF-8\"?>",
                                           "<?xml version='1.0'?>",
                                           " encoding=\"",
                                           "latin1",
                                           "UTF-8",
                                           "<!DOCTYPE ",
                                           "<1 ",
                                           "< a>",
                                           "&#",
                                           "&#x",
                                           ";",
                                           "#1;",
                                           "x1;",
                                           "&amp;",
                                           "&lt;",
                                           "&quot;",
                                           "\xe0",
                                           "\xc3",
                                           "\xf0",
                                           "\xef\xbb\xbf",
                                           "\xef\xbf\xbe",
                                           "<\xc3\xa9>",
                                           "</\xc3\xa9>",
                                           " e=\"",
                                           " f='",
                                           "<_>",
                                           "</_>",
                                           "<a:b.c-d>",
                                           "</a:b.c-d>",
                                           std::string(1, '\0'),
                                           "<a >",
                                           "</a >",
                                           "\t"};
  std::mt19937 random(42);
  std::uniform_int_distribution<std::size_t> piece(0, pieces.size() - 1);
  std::uniform_int_distribution<int> length(1, 40);
  int exact = 0;
  int parsed_cleanly = 0;
  for (int round = 0; round < 20000; ++round) {
    std::string text;
    for (int n = length(random); n > 0; --n) text += pieces[piece(random)];
    const Parsed parsed = tinyxml_parse(text);
    const std::size_t walked = tinyxml_element_depth(text, 1000);
    ASSERT_GE(walked, parsed.depth) << "counted less than TinyXML nests in: " << text;
    if (!parsed.error) {
      ++parsed_cleanly;
      EXPECT_EQ(walked, parsed.depth) << "counted more than TinyXML nests in: " << text;
    }
    exact += walked == parsed.depth ? 1 : 0;
  }
  // Enough of the texts exercise the walk's agreement, not just its bound.
  EXPECT_GT(parsed_cleanly, 1000);
  EXPECT_GT(exact, 18000);
}

}  // namespace
}  // namespace pixelgym::engine
