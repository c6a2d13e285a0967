// SPDX-License-Identifier: MIT
// The Halmstad label CSV reader: every class with its id, MATLAB's half-pixel shift, and errors that name the file,
// the line and the field.
#include <wingman/common/detection_class.hpp>
#include <wingman/training/halmstad_labels.hpp>
#include <wingman/training/yolo_dataset.hpp>

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <string>

namespace wingman::training {
namespace {

std::string write(const testing::TempDir& dir, const std::string& text) {
  const std::string path = dir.file("V_TEST_001.csv");
  std::ofstream(path) << text;
  return path;
}

std::string label_error_of(const std::string& path) {
  try {
    read_halmstad_labels(path);
  } catch (const DatasetError& e) {
    return e.what();
  }
  return "no error";
}

TEST(HalmstadLabels, EveryClassWithItsIdAndTheHalfPixelShift) {
  testing::TempDir dir;
  const auto boxes =
      read_halmstad_labels(write(dir,
                                 "frame,class,x,y,w,h\r\n0,DRONE,10.5,20,4,3\r\n\n"
                                 "0,BIRD,100,50,6,5\n7,AIRPLANE,1,2,30,10\n7,HELICOPTER,200,100,40,20\n"));
  ASSERT_EQ(boxes.size(), 2u);
  ASSERT_EQ(boxes.at(0).size(), 2u);
  EXPECT_EQ(boxes.at(0)[0].cls, 0);
  EXPECT_DOUBLE_EQ(boxes.at(0)[0].rect.x, 10.0);
  EXPECT_DOUBLE_EQ(boxes.at(0)[0].rect.y, 19.5);
  EXPECT_DOUBLE_EQ(boxes.at(0)[0].rect.width, 4.0);
  EXPECT_EQ(boxes.at(0)[1].cls, 2);
  ASSERT_EQ(boxes.at(7).size(), 2u);
  EXPECT_EQ(boxes.at(7)[0].cls, 1);
  EXPECT_EQ(boxes.at(7)[1].cls, 3);
  EXPECT_EQ(halmstad_class_id("HELICOPTER"), 3);
  EXPECT_EQ(halmstad_class_id("drone"), -1);  // the names are the CSVs' upper-case ones
  // The label classes are the detector's, in its order (the import names them from common::kDetectionClassNames).
  for (size_t i = 0; i < common::kDetectionClassNames.size(); ++i) {
    std::string upper = common::kDetectionClassNames[i];
    std::transform(upper.begin(), upper.end(), upper.begin(), [](unsigned char c) { return std::toupper(c); });
    EXPECT_EQ(halmstad_class_id(upper), static_cast<int>(i)) << upper;
  }
}

TEST(HalmstadLabels, SplitKeepsEmptyFieldsAndDropsCarriageReturns) {
  EXPECT_EQ(split_csv_line("a,,b\r"), (std::vector<std::string>{"a", "", "b"}));
  EXPECT_EQ(split_csv_line("V_DRONE_001,DRONE,,CLOSE,"),
            (std::vector<std::string>{"V_DRONE_001", "DRONE", "", "CLOSE", ""}));
}

TEST(HalmstadLabels, ErrorsNameTheFileLineAndField) {
  testing::TempDir dir;
  EXPECT_NE(label_error_of(dir.file("absent.csv")).find("absent.csv: cannot read the label file"), std::string::npos);
  EXPECT_NE(label_error_of(write(dir, "frame,x,y\n")).find("V_TEST_001.csv:1: expected the header"), std::string::npos);
  EXPECT_NE(label_error_of(write(dir, "frame,class,x,y,w,h\n0,KITE,1,1,2,2\n"))
                .find("V_TEST_001.csv:2: field class = 'KITE': expected DRONE, AIRPLANE, BIRD or HELICOPTER"),
            std::string::npos);
  EXPECT_NE(label_error_of(write(dir, "frame,class,x,y,w,h\n0,DRONE,1,1,2,2\n4294967296,DRONE,1,1,2,2\n"))
                .find("V_TEST_001.csv:3: field frame = '4294967296'"),
            std::string::npos);
  EXPECT_NE(
      label_error_of(write(dir, "frame,class,x,y,w,h\n0,BIRD,1,1,0,2\n")).find("field w = '0': expected a positive"),
      std::string::npos);
  EXPECT_NE(label_error_of(write(dir, "frame,class,x,y,w,h\n0,BIRD,1,1,2\n")).find(":2: expected 6 fields, got 5"),
            std::string::npos);
}

}  // namespace
}  // namespace wingman::training
