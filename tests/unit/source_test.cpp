#include <doctest/doctest.h>

#include "frontend/source.h"

using namespace psys;

TEST_CASE("line and column of byte offsets") {
    SourceFile f("a.psys", "ab\ncd\n\nef");
    CHECK(f.lineColumn(0).line == 1);
    CHECK(f.lineColumn(0).column == 1);
    CHECK(f.lineColumn(2).column == 3);  // the newline itself is on line 1
    CHECK(f.lineColumn(3).line == 2);
    CHECK(f.lineColumn(4).column == 2);
    CHECK(f.lineColumn(6).line == 3);
    CHECK(f.lineColumn(7).line == 4);
    CHECK(f.lineText(2) == "cd");
    CHECK(f.lineText(3) == "");
    CHECK(f.lineText(4) == "ef");
    CHECK(f.lineText(9) == "");
}

TEST_CASE("line text drops a Windows line ending") {
    SourceFile f("a.psys", "x = 1;\r\ny = 2;\r\n");
    CHECK(f.lineText(1) == "x = 1;");
    CHECK(f.lineColumn(8).line == 2);
}

TEST_CASE("joining ranges spans both and ignores invalid ones") {
    SourceRange a{0, 4, 6}, b{0, 10, 12}, none{};
    CHECK(SourceRange::join(a, b).begin == 4);
    CHECK(SourceRange::join(a, b).end == 12);
    CHECK(SourceRange::join(none, b).begin == 10);
    CHECK(SourceRange::join(a, none).end == 6);
}

TEST_CASE("UTF-8: the first byte that does not begin a well-formed sequence") {
    using psys::firstInvalidUtf8;
    CHECK_FALSE(firstInvalidUtf8("plain ASCII").has_value());
    CHECK_FALSE(firstInvalidUtf8("caf\xC3\xA9 \xE2\x98\x95 \xF0\x9D\x84\x9E").has_value());  // é ☕ 𝄞
    CHECK(firstInvalidUtf8("caf\xE9!") == 3u);             // Latin-1 é
    CHECK(firstInvalidUtf8("a\xC0\x80") == 1u);            // an overlong NUL
    CHECK(firstInvalidUtf8("ab\xE0\x80\x80") == 2u);       // an overlong three-byte form
    CHECK(firstInvalidUtf8("\xED\xA0\x80") == 0u);         // a surrogate
    CHECK(firstInvalidUtf8("x\xF4\x90\x80\x80") == 1u);    // past U+10FFFF
    CHECK(firstInvalidUtf8("ok\xE2\x98") == 2u);           // cut short at the end
    CHECK(firstInvalidUtf8("\x80") == 0u);                 // a lone continuation byte
}
