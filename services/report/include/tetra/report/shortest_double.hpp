#pragma once
// A double in shortest round-trip form, the text std::to_chars(first, last, value) gives (and
// tetra::format_double: "nan" for any NaN), about twice as fast: the digits from fmt's Dragonbox (the
// same shortest, closest digits as the Ryu inside libstdc++), laid out as to_chars lays them out (fixed
// unless scientific is shorter). Values to_chars would print with more digits than the shortest
// (whole numbers from 2^53 on, in fixed form) go through std::to_chars itself.

namespace tetra::report {

//! format_double(first, value)'s text at `first` (room for kMaxDoubleChars); returns its end.
char* format_shortest(char* first, double value);

}  // namespace tetra::report
