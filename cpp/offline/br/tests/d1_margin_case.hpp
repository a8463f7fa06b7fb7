// The margin model the weakened-train checks of the margin and falsifier tests share: a train
// type on the up running line of the generated D1 test line, and that line's end of track.
#pragma once

#include <string>

#include "railproof/br/analysis/margins.hpp"
#include "railproof/offline/line.hpp"
#include "railproof/testing/gen_data.hpp"

namespace railproof::br::analysis {

// The generated D1 test line.
inline offline::Line D1() { return offline::LoadLine(testing::GenDir() / "lines" / "d1_test_line.json"); }

// The end of track of D1's up line (10 m class margin).
inline const Location kD1EndOfTrack{LocationClass::kEndOfTrack, "end of track", 14'500'000, 10'000, 14'490'000};

// `train` (a provided or a negative-test type) on D1's up line with the reference speed-error
// model; the model refers to the line, so both live here.
struct D1UpModel {
  explicit D1UpModel(const std::string& train)
      : line(D1()), model(line.Running("up"), testing::Train(train), ReferenceSpeedErrorModel()) {}
  offline::Line line;
  MarginModel model;
};

}  // namespace railproof::br::analysis
