// Identity of the stamping FMU binary (export/stamping_fmu.cpp), shared with the writer of
// its modelDescription.xml (fmu/export.cpp): the two must agree.
#pragma once

namespace plcfi::plant::fmu {

inline constexpr const char* kStampingFmuGuid = "{5f0c1d2e-7a43-4b8e-9c61-3d2a8e4f7b10}";
inline constexpr const char* kStampingFmuIdentifier = "stamping";
// The Integer parameter that seeds the plant's random variation.
inline constexpr unsigned kStampingFmuSeedRef = 1000;
// The plant's statistics (workpieces_stamped, ...) are local Integer variables from here on,
// in the order StampingPlant::stats() gives them.
inline constexpr unsigned kStampingFmuStatsRef = 2000;
// File name of the binary, next to the plcfi executable.
inline constexpr const char* kStampingFmuLibrary = "plcfi_stamping_fmu.so";

}  // namespace plcfi::plant::fmu
