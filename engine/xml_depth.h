// How deeply TinyXML 2.6 (the XML parser under urdfdom) nests elements while parsing a text, found
// without parsing it.
#pragma once

#include <cstddef>
#include <string>

namespace pixelgym::engine {

/// The deepest nesting of elements TinyXML 2.6's TiXmlDocument::Parse reaches on `text`, or a
/// number > `stop_after` as soon as it exceeds `stop_after`.
///
/// TinyXML parses each element by recursion, and frees and prints its tree by recursion: a file
/// nested 50,000 deep overflowed the stack. This walks the text the way TinyXML's parser does (its
/// node identification, its attribute and text reading with their entity and UTF-8 handling, its
/// switch to UTF-8 after a declaration), with a loop instead of recursion, so that a file can be
/// refused before TinyXML sees it. Where TinyXML would stop at an error this may go on reading, so
/// it never counts less than TinyXML reaches, only, for some malformed files, more. TinyXML reads
/// `text.c_str()`; bytes past the end of `text` are counted as zeros, so TinyXML must be given at
/// least 4 zero bytes after the text (see kTinyXmlPadding) for the two to read the same bytes: a
/// UTF-8 lead byte makes TinyXML step over up to 3 bytes without looking at them, past the end of
/// the text when it is the last byte.
std::size_t tinyxml_element_depth(const std::string& text, std::size_t stop_after);

/// How many zero bytes to append to a text handed to TinyXML so that it never reads past the
/// buffer (see tinyxml_element_depth).
inline constexpr std::size_t kTinyXmlPadding = 8;

}  // namespace pixelgym::engine
