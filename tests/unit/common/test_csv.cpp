// One CSV field as RFC 4180 writes it (common/csv.hpp), shared by every CSV plcfi writes.
#include <gtest/gtest.h>

#include "common/csv.hpp"

using plcfi::common::csv_field;

TEST(CsvField, PlainTextStaysAsItIs) {
  EXPECT_EQ(csv_field(""), "");
  EXPECT_EQ(csv_field("Main.level"), "Main.level");
  EXPECT_EQ(csv_field("a;b 'c'"), "a;b 'c'");
}

TEST(CsvField, CommaQuoteAndLineBreaksAreQuoted) {
  EXPECT_EQ(csv_field("a,b"), "\"a,b\"");
  EXPECT_EQ(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
  EXPECT_EQ(csv_field("two\nlines"), "\"two\nlines\"");
  EXPECT_EQ(csv_field("cr\r"), "\"cr\r\"");  // a bare CR would end the record in some readers
}
