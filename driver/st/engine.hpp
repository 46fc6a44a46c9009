// The ST engine's front door: load, parse and compile files (build.hpp); resolve variable
// paths to typed handles and read and write values (handles.hpp); disassemble, report
// branch coverage and describe traps (listing.hpp).
#pragma once

#include "build.hpp"
#include "handles.hpp"
#include "listing.hpp"
