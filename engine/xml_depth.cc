#include "pixelgym/engine/xml_depth.h"

#include <algorithm>
#include <cstring>
#include <vector>

namespace pixelgym::engine {
namespace {

// Each function below mirrors the TinyXML 2.6.2 function of the same name (tinyxmlparser.cpp):
// positions stand for its pointers, kNull for its null pointer. The comments name where TinyXML
// behaves in ways an XML reader would not expect; each of them made an earlier, simpler count
// disagree with TinyXML's.
constexpr std::size_t kNull = static_cast<std::size_t>(-1);

enum class Encoding { kUnknown, kUtf8, kLegacy };

// TinyXML's utf8ByteTable: how many bytes a UTF-8 character starting with `byte` takes. In UTF-8
// mode TinyXML steps over that many bytes without looking at them, so a lead byte hides the quote,
// '<' or end of text that follows it.
int utf8_length(unsigned char byte) {
  if (byte >= 0xc2 && byte <= 0xdf) return 2;
  if (byte >= 0xe0 && byte <= 0xef) return 3;
  if (byte >= 0xf0 && byte <= 0xf4) return 4;
  return 1;
}

// TinyXML classifies bytes with the C library's isspace/isalpha/isalnum, which agree with these in
// every glibc locale for bytes below 127; from 127 up every byte is a letter.
bool is_space(unsigned char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r';
}
bool is_alpha(unsigned char c) {
  return c >= 127 || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z');
}
bool is_alnum(unsigned char c) { return is_alpha(c) || (c >= '0' && c <= '9'); }
unsigned char lower(unsigned char c) {
  return c >= 'A' && c <= 'Z' ? static_cast<unsigned char>(c - 'A' + 'a') : c;
}

class TinyXmlWalk {
 public:
  explicit TinyXmlWalk(const std::string& text) : text_(text) {}

  std::size_t deepest(std::size_t stop_after) {
    // TiXmlDocument::Parse: a byte order mark selects UTF-8 from the start; otherwise the first
    // declaration at the top level chooses the encoding for the rest of the file.
    if (at(0) == 0xef && at(1) == 0xbb && at(2) == 0xbf) encoding_ = Encoding::kUtf8;
    std::vector<std::pair<std::size_t, std::size_t>> open;  // names of the open elements
    std::size_t deepest = 0;
    std::size_t p = skip_white_space(0);
    while (p != kNull && at(p) != 0) {
      const bool top = open.empty();
      if (at(p) != '<') {
        if (top) break;  // Identify() finds no node: the document ends.
        p = parse_text(p);
      } else if (!top && string_equal(p, "</", false)) {
        p = parse_end_tag(p, open.back());
        if (p == kNull) break;
        open.pop_back();
      } else {
        switch (identify(p)) {
          case Node::kDeclaration: {
            std::string value;
            p = parse_declaration(p, &value);
            if (top && encoding_ == Encoding::kUnknown) choose_encoding(value);
            break;
          }
          case Node::kComment:
            p = parse_comment(p);
            break;
          case Node::kCdata:
            p = parse_cdata(p);
            break;
          case Node::kUnknown:
            p = parse_unknown(p);
            break;
          case Node::kElement: {
            deepest = std::max(deepest, open.size() + 1);
            if (deepest > stop_after) return deepest;
            std::pair<std::size_t, std::size_t> name;
            bool has_content = false;
            p = parse_element_tag(p, &name, &has_content);
            if (has_content) open.push_back(name);
            break;
          }
        }
      }
      p = skip_white_space(p);
    }
    return deepest;
  }

 private:
  enum class Node { kDeclaration, kComment, kCdata, kUnknown, kElement };

  // The byte TinyXML reads at `p`: the text's, then zeros (the padding the caller adds).
  unsigned char at(std::size_t p) const {
    return p < text_.size() ? static_cast<unsigned char>(text_[p]) : 0;
  }

  std::size_t skip_white_space(std::size_t p) const {
    if (p == kNull || at(p) == 0) return kNull;
    while (at(p) != 0) {
      if (encoding_ == Encoding::kUtf8 && at(p) == 0xef &&
          ((at(p + 1) == 0xbb && at(p + 2) == 0xbf) ||
           (at(p + 1) == 0xbf && (at(p + 2) == 0xbe || at(p + 2) == 0xbf)))) {
        p += 3;  // byte order marks and two non-characters count as white space
      } else if (is_space(at(p))) {
        ++p;
      } else {
        break;
      }
    }
    return p;
  }

  // Whether the text at `p` starts with `tag`.
  bool string_equal(std::size_t p, const char* tag, bool ignore_case) const {
    if (p == kNull || at(p) == 0) return false;
    for (; *tag != 0; ++p, ++tag) {
      const unsigned char c = at(p);
      const auto t = static_cast<unsigned char>(*tag);
      if (c == 0 || (ignore_case ? lower(c) != lower(t) : c != t)) return false;
    }
    return true;
  }

  std::size_t read_name(std::size_t p, std::pair<std::size_t, std::size_t>* name) const {
    if (p == kNull || !(is_alpha(at(p)) || at(p) == '_')) return kNull;
    const std::size_t start = p;
    while (is_alnum(at(p)) || at(p) == '_' || at(p) == '-' || at(p) == '.' || at(p) == ':') ++p;
    if (name != nullptr) *name = {start, p - start};
    return p;
  }

  // strchr: the first `c` from `p` on, before the first zero byte.
  std::size_t find(std::size_t p, char c) const {
    for (; at(p) != 0; ++p) {
      if (at(p) == static_cast<unsigned char>(c)) return p;
    }
    return kNull;
  }

  // A character reference reaches to the first ';' after it, whatever lies between, when the
  // bytes just before that ';' are digits after a '#' (or hex digits after an 'x'): "&#<!--#1;" is
  // one character, and what follows it is parsed.
  std::size_t get_entity(std::size_t p, std::string* value) const {
    if (at(p + 1) == '#' && at(p + 2) != 0) {
      const bool hex = at(p + 2) == 'x';
      if (hex && at(p + 3) == 0) return kNull;
      std::size_t q = find(p + (hex ? 3 : 2), ';');
      if (q == kNull) return kNull;
      const std::size_t delta = q - p;
      --q;
      unsigned long ucs = 0;  // NOLINT(runtime/int): TinyXML's type, so that it wraps the same
      unsigned mult = 1;
      while (at(q) != (hex ? 'x' : '#')) {
        const unsigned char c = at(q);
        unsigned digit = 0;
        if (c >= '0' && c <= '9') {
          digit = c - '0';
        } else if (hex && c >= 'a' && c <= 'f') {
          digit = c - 'a' + 10;
        } else if (hex && c >= 'A' && c <= 'F') {
          digit = c - 'A' + 10;
        } else {
          return kNull;
        }
        ucs += mult * digit;
        mult *= hex ? 16 : 10;
        --q;
      }
      // Only a declaration's value is kept, read before the encoding is chosen: one byte.
      if (value != nullptr) value->push_back(static_cast<char>(ucs));
      return p + delta + 1;
    }
    static const std::pair<const char*, char> kEntities[] = {
        {"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&apos;", '\''}};
    for (const auto& [name, character] : kEntities) {
      if (string_equal(p, name, false)) {
        if (value != nullptr) value->push_back(character);
        return p + std::strlen(name);
      }
    }
    if (value != nullptr) value->push_back('&');
    return p + 1;
  }

  std::size_t get_char(std::size_t p, std::string* value) const {
    const int length = encoding_ == Encoding::kUtf8 ? utf8_length(at(p)) : 1;
    if (length == 1) {
      if (at(p) == '&') return get_entity(p, value);
      if (value != nullptr) value->push_back(static_cast<char>(at(p)));
      return p + 1;
    }
    // UTF-8 mode only, where values are not kept.
    return p + static_cast<std::size_t>(length);
  }

  // Up to and past `end`; kNull when the text ends first or right after it.
  std::size_t read_text(std::size_t p, const char* end, bool trim, std::string* value) const {
    if (trim) p = skip_white_space(p);
    while (p != kNull && at(p) != 0 && !string_equal(p, end, false)) {
      p = trim && is_space(at(p)) ? p + 1 : get_char(p, value);
    }
    if (p != kNull && at(p) != 0) p += std::strlen(end);
    return p != kNull && at(p) != 0 ? p : kNull;
  }

  Node identify(std::size_t p) const {
    if (string_equal(p, "<?xml", true)) return Node::kDeclaration;
    if (string_equal(p, "<!--", false)) return Node::kComment;
    if (string_equal(p, "<![CDATA[", false)) return Node::kCdata;
    if (string_equal(p, "<!", false)) return Node::kUnknown;
    // Only a letter, '_' or a byte >= 127 after '<' starts an element. Anything else ("<1", "< a",
    // "<\"") is an unknown node, which ends at the next '>' even inside quotes.
    if (is_alpha(at(p + 1)) || at(p + 1) == '_') return Node::kElement;
    return Node::kUnknown;
  }

  std::size_t parse_unknown(std::size_t p) const {
    ++p;
    while (at(p) != 0 && at(p) != '>') ++p;
    return at(p) == '>' ? p + 1 : p;
  }

  std::size_t parse_comment(std::size_t p) const {
    p += 4;
    while (at(p) != 0 && !string_equal(p, "-->", false)) ++p;
    return at(p) != 0 ? p + 3 : p;
  }

  std::size_t parse_cdata(std::size_t p) const {
    p += 9;
    while (at(p) != 0 && !string_equal(p, "]]>", false)) ++p;
    return read_text(p, "]]>", false, nullptr);
  }

  // Text up to the next '<' (which is not consumed).
  std::size_t parse_text(std::size_t p) const {
    p = read_text(p, "<", true, nullptr);
    return p != kNull ? p - 1 : kNull;
  }

  // name="value", name='value' or name=value; the value read as text, entities and all.
  std::size_t parse_attribute(std::size_t p, std::string* value) const {
    p = skip_white_space(p);
    if (p == kNull) return kNull;
    p = read_name(p, nullptr);
    if (p == kNull || at(p) == 0) return kNull;
    p = skip_white_space(p);
    if (p == kNull || at(p) != '=') return kNull;
    p = skip_white_space(p + 1);
    if (p == kNull) return kNull;
    if (at(p) == '\'' || at(p) == '"') {
      const char quote[2] = {static_cast<char>(at(p)), 0};
      return read_text(p + 1, quote, false, value);
    }
    while (at(p) != 0 && !is_space(at(p)) && at(p) != '/' && at(p) != '>') {
      if (at(p) == '\'' || at(p) == '"') return kNull;
      if (value != nullptr) value->push_back(static_cast<char>(at(p)));
      ++p;
    }
    return p;
  }

  // <?xml ... >: version, encoding and standalone are read as attributes (quotes hide '>'),
  // anything else is skipped to white space or '>'. `encoding` receives the encoding's value.
  std::size_t parse_declaration(std::size_t p, std::string* encoding) const {
    p += 5;
    while (p != kNull && at(p) != 0) {
      if (at(p) == '>') return p + 1;
      p = skip_white_space(p);
      if (p == kNull) return kNull;
      if (string_equal(p, "version", true) || string_equal(p, "standalone", true)) {
        p = parse_attribute(p, nullptr);
      } else if (string_equal(p, "encoding", true)) {
        encoding->clear();
        p = parse_attribute(p, encoding);
      } else {
        while (at(p) != 0 && at(p) != '>' && !is_space(at(p))) ++p;
      }
    }
    return kNull;
  }

  void choose_encoding(const std::string& value) {
    const std::string name = value.substr(0, value.find('\0'));  // TinyXML reads it as a C string
    encoding_ = name.empty() || string_starts(name, "utf-8") || string_starts(name, "utf8")
                    ? Encoding::kUtf8
                    : Encoding::kLegacy;
  }

  static bool string_starts(const std::string& text, const char* prefix) {
    const std::size_t length = std::strlen(prefix);
    if (text.size() < length) return false;
    for (std::size_t i = 0; i < length; ++i) {
      if (lower(static_cast<unsigned char>(text[i])) != static_cast<unsigned char>(prefix[i]))
        return false;
    }
    return true;
  }

  // "<name attributes" then "/>" (no content) or ">" (content follows: `has_content`).
  std::size_t parse_element_tag(std::size_t p, std::pair<std::size_t, std::size_t>* name,
                                bool* has_content) const {
    p = read_name(skip_white_space(p + 1), name);
    if (p == kNull || at(p) == 0) return kNull;
    while (p != kNull && at(p) != 0) {
      p = skip_white_space(p);
      if (p == kNull) return kNull;
      if (at(p) == '/') return at(p + 1) == '>' ? p + 2 : kNull;
      if (at(p) == '>') {
        *has_content = true;
        return p + 1;
      }
      // TinyXML refuses a repeated attribute name; not checking it only reads on further.
      p = parse_attribute(p, nullptr);
      if (p == kNull || at(p) == 0) return kNull;
    }
    return kNull;
  }

  // "</name", white space, ">". (Some TinyXML builds accept only "</name>": reading on where
  // they stop is safe.)
  std::size_t parse_end_tag(std::size_t p, std::pair<std::size_t, std::size_t> name) const {
    p += 2;
    for (std::size_t i = 0; i < name.second; ++i, ++p) {
      if (at(p) != at(name.first + i)) return kNull;
    }
    p = skip_white_space(p);
    return p != kNull && at(p) == '>' ? p + 1 : kNull;
  }

  const std::string& text_;
  Encoding encoding_ = Encoding::kUnknown;
};

}  // namespace

std::size_t tinyxml_element_depth(const std::string& text, std::size_t stop_after) {
  return TinyXmlWalk(text).deepest(stop_after);
}

}  // namespace pixelgym::engine
