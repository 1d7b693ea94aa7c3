#include <gtest/gtest.h>

#include "cohort/scene/lexer.h"

using namespace cohort::scene;

TEST(Lexer, TokenKindsLinesAndComments) {
  Lexer lex("name \"quoted string\" 12.5 -3 // comment\n/* multi\nline */ textures/base/floor1.tga { } == 1e-3", "t.txt");
  Token t = lex.next();
  EXPECT_EQ(t.kind, Token::Kind::Name);
  EXPECT_EQ(t.text, "name");
  t = lex.next();
  EXPECT_EQ(t.kind, Token::Kind::String);
  EXPECT_EQ(t.text, "quoted string");
  EXPECT_DOUBLE_EQ(lex.expect_number("x"), 12.5);
  EXPECT_DOUBLE_EQ(lex.expect_number("y"), -3.0);
  t = lex.next();
  EXPECT_EQ(t.kind, Token::Kind::Name);
  EXPECT_EQ(t.text, "textures/base/floor1.tga");
  EXPECT_EQ(t.line, 3);
  EXPECT_EQ(t.column, 9);
  lex.expect("{");
  lex.expect("}");
  EXPECT_EQ(lex.next().text, "==");
  EXPECT_DOUBLE_EQ(lex.expect_number("z"), 1e-3);
  EXPECT_TRUE(lex.at_end());
  EXPECT_EQ(lex.next().kind, Token::Kind::End);
}

TEST(Lexer, ErrorsCarryFileLineColumn) {
  try {
    Lexer lex("a\n  \"never closed\n", "f.mtr");
    lex.next();
    lex.next();
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), "f.mtr");
    EXPECT_EQ(e.line(), 2);
    EXPECT_EQ(e.column(), 3);
    EXPECT_STREQ(e.what(), "f.mtr:2:3: unterminated string");
  }
  Lexer comment("x /* open\n\n", "c.proc");
  comment.next();
  EXPECT_THROW(comment.next(), ParseError);
}

TEST(Lexer, CountsTheFileCannotHoldAreRejected) {
  Lexer lex("1000000 0 0", "n.proc");
  EXPECT_THROW(lex.expect_count("vertex count", 16), ParseError);
  Lexer ok("3 ( 1 2 3 ) ( 4 5 6 ) ( 7 8 9 )", "n.proc");
  EXPECT_EQ(ok.expect_count("points", 7), 3u);
}

TEST(Lexer, NumbersOutOfRangeAndNegativeCountsFail) {
  Lexer big("1e999", "n.txt");
  EXPECT_THROW(big.next(), ParseError);
  Lexer negative("-4", "n.txt");
  EXPECT_THROW(negative.expect_count("count", 1), ParseError);
  Lexer fraction("2.5", "n.txt");
  EXPECT_THROW(fraction.expect_integer("count"), ParseError);
}

TEST(Lexer, BracedBlockTextAndSkipping) {
  Lexer lex("mat { a { b } c } next", "m.mtr");
  lex.next();
  Token open = lex.next();
  EXPECT_EQ(lex.braced_block_text(open), " a { b } c ");
  EXPECT_EQ(lex.next().text, "next");
  Lexer unbalanced("{ { }", "m.mtr");
  unbalanced.next();
  EXPECT_THROW(unbalanced.skip_braced_block(), ParseError);
}
