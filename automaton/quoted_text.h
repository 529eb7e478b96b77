#pragma once

#include <string>
#include <string_view>

namespace hybrid {

/// `text` made safe to print in a message to a terminal: every byte a terminal would act on
/// instead of showing is written as an escape, so that a name or a data cell taken from an input
/// file can neither move the cursor, recolour or clear the screen nor split a message across
/// lines. Escapes: `\n`, `\r`, `\t`; `\xHH` (two lower-case hex digits) for the other control
/// bytes 0x00-0x1F and 0x7F and for every byte that is not part of well-formed UTF-8; `\u0080` ...
/// `\u009f` for the C1 control characters U+0080 to U+009F (which some terminals obey).
/// Everything else (printable ASCII, well-formed UTF-8, and the backslash itself) is kept, so
/// that text without such bytes, paths with backslashes included, reads unchanged, and escaping
/// is idempotent: escaping a message that quotes an already escaped name changes nothing.
/// Never throws but std::bad_alloc.
std::string EscapedForMessage(std::string_view text);

/// EscapedForMessage(text) in single quotes: how messages quote a name or a value taken from an
/// input (`unknown column 'a\x1b[2J'`).
std::string QuotedForMessage(std::string_view text);

}  // namespace hybrid
