#pragma once
// Reading and writing the ASCII FAP format of Xface, Greta and VREng.
//
//   # comment lines (first non-blank character '#') and blank lines anywhere
//   2.1 name with spaces or C:\a\path 25 108      <- version name fps count
//   0 0 1 1 ... (68 tokens; any non-zero = transmitted)   <- mask, frame 1
//   0 12 -30 ...                                           <- values, frame 1
//   ...
//
// Header: the first token is the version (2.0 and 2.1 are known; another
// number is read with a warning), the last two are the frame rate (> 0, may be
// fractional) and the declared frame count; what lies between is the name.
// A count that differs from the frames present is a warning. A count above
// kMaxFapFrames is an error (no file of that size is real).
//
// No header: when the first line that is not a comment is already a mask
// line (68 or 69 numeric tokens), the file is read as version 2.1 at
// kHeaderlessFps with a warning. Any other first line that is not a header
// is an error.
//
// Frames: a mask line of 68 tokens, or 69 as Greta's Java writer produces
// (the extra token is ignored, with one warning); then a values line: the
// frame number (an integer >= 0), then one entry per transmitted FAP in FAP
// order. FAP 1 takes 4 values (select1 select2 blend def) or 1 (select1);
// FAP 2 takes 6 (select1 intensity1 select2 intensity2 init_face def) or 1
// (select1); the token count tells which. Values are integers or decimals.
// Tokens are separated by spaces or tabs; lines end in LF, CRLF or CR; a
// leading UTF-8 byte order mark is skipped.
// Trailing frames that transmit nothing are dropped (with a warning): under
// the untransmitted-FAP rule they change nothing (Greta writes one such frame
// for an empty animation).
//
// Every error is emoface::InputError "fap: FILE:LINE: expected ..., found ...".
#include <string>
#include <string_view>

#include "emoface/fap/fap_stream.h"

namespace emoface::fap {

inline constexpr double kHeaderlessFps = 25;
inline constexpr long long kMaxFapFrames = 1'000'000;  // 11 hours at 25 fps
inline constexpr long long kMaxFapFileBytes = 256LL << 20;  // real files are KBs

FapStream read_fap_file(const std::string& path);
// source_name is what messages call the text ("anim.fap").
FapStream parse_fap(std::string_view text, const std::string& source_name);

// The format above: header, then per frame the 68-token mask (the frame's
// mask, not its non-zero values) and the values line; FAP 1 and 2 in their
// full forms, numbers in the shortest form that reads back exactly, LF line
// ends. parse_fap(format_fap(s)) == s for every stream the writer accepts.
// Throws emoface::InputError for what the format cannot carry: a name with a
// line break or outer whitespace, a version that is not a number like 2.1,
// an fps that is not finite and positive, a negative frame number, a value
// that is not finite.
std::string format_fap(const FapStream& stream);
// Writes to a temporary file in the same folder, then renames it over path.
void write_fap_file(const FapStream& stream, const std::string& path);

// Same version, name, fps and frames (warnings are not compared).
bool same_content(const FapStream& a, const FapStream& b);

// The stream as Xface's FAP reader takes it and plays it the way emoface
// does (Xface 1.0's FAPFile::open, XFace/src/XFace/FapFile.cpp, Xface Core
// Library, ITC-irst/FBK 2004-2008, MPL 1.1). That reader pulls
// whitespace-separated tokens with istream >>, so:
//  - the name is one token of at most 254 bytes (read into a char[255]):
//    whitespace runs become '_', an empty name "emoface";
//  - the frame rate is read into a short (or as a float truncated to one):
//    a fractional rate is resampled at the nearest whole one (1..32767),
//    values interpolated as FapStream::sample does;
//  - a frame's number indexes the frame table the header's count sized,
//    unchecked: frames are numbered 0..n-1 (emoface times frame k at k / fps
//    whatever its number, so this changes no timing);
//  - a FAP a frame does not transmit is 0 there (no hold): every frame
//    transmits what it holds (resolve_untransmitted);
//  - values are MPEG-4's integers, as Xface's own files hold them (rounded).
// '#' lines only before the header, 68-token masks, FAP 1 as 4 values and
// FAP 2 as 6 are what format_fap writes anyway. Throws emoface::InputError
// for an empty stream (Xface's rewind() reads frame 0) and for a value that
// is not finite or lies beyond an int's range.
FapStream for_xface(const FapStream& stream);

}  // namespace emoface::fap
