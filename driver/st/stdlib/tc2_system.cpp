// Beckhoff's Tc2_System library, the parts TwinCAT projects use, written from its public
// documentation (infosys.beckhoff.com, "Tc2_System"): what can be ST is ST here; MEMCPY,
// MEMSET, MEMCMP, MEMMOVE, ADSLOGSTR, ADSLOGDINT, ADSLOGLREAL and TIME() are built-ins
// (sema/stdfuncs.cpp, vm/cpp_functions.cpp) because they reach memory, the log or the clock.
// Under --dialect codesys an application gets the items its sources name and do not
// declare (st/build.cpp), as the library "<Tc2_System>".
#include <algorithm>

#include "codegen/compiler.hpp"
#include "syntax/source.hpp"

namespace plcfi::st {

const std::vector<Tc2Item>& tc2_system_items() {
  // The ADSLOG control masks (ORed together): the first three are the message's level,
  // the others what TwinCAT does with it (log book, message box), which plcfi's log has
  // no use for; they are accepted and ignored.
  static const std::vector<Tc2Item> items = {
      {"ADSLOG_MSGTYPE_HINT", "VAR_GLOBAL CONSTANT ADSLOG_MSGTYPE_HINT : DWORD := 16#01; END_VAR\n", nullptr},
      {"ADSLOG_MSGTYPE_WARN", "VAR_GLOBAL CONSTANT ADSLOG_MSGTYPE_WARN : DWORD := 16#02; END_VAR\n", nullptr},
      {"ADSLOG_MSGTYPE_ERROR", "VAR_GLOBAL CONSTANT ADSLOG_MSGTYPE_ERROR : DWORD := 16#04; END_VAR\n", nullptr},
      {"ADSLOG_MSGTYPE_LOG", "VAR_GLOBAL CONSTANT ADSLOG_MSGTYPE_LOG : DWORD := 16#10; END_VAR\n", nullptr},
      {"ADSLOG_MSGTYPE_MSGBOX", "VAR_GLOBAL CONSTANT ADSLOG_MSGTYPE_MSGBOX : DWORD := 16#20; END_VAR\n", nullptr},
      {"ADSLOG_MSGTYPE_RESOURCE", "VAR_GLOBAL CONSTANT ADSLOG_MSGTYPE_RESOURCE : DWORD := 16#40; END_VAR\n", nullptr},
      {"ADSLOG_MSGTYPE_STRING", "VAR_GLOBAL CONSTANT ADSLOG_MSGTYPE_STRING : DWORD := 16#80; END_VAR\n", nullptr},
      // The length of T_MaxString.
      {"MAX_STRING_LENGTH", "VAR_GLOBAL CONSTANT MAX_STRING_LENGTH : UDINT := 255; END_VAR\n", nullptr},
      // An address: pointers and ADR() are 32 bits wide in this engine's memory, so PVOID
      // is a UDINT (TwinCAT's is pointer-sized, 64 bits on x64 targets).
      {"PVOID", "TYPE PVOID : UDINT; END_TYPE\n", nullptr},
      // CODESYS's BIT packs consecutive members of a structure into one byte. plcfi lays
      // out no packed bits: a BIT member is a BOOL of its own byte, with the same values
      // and the same reads and writes, but SIZEOF of such a structure is larger than on
      // the PLC and MEMCPY of it copies a different layout.
      {"BIT", "TYPE BIT : BOOL; END_TYPE\n", nullptr},
      // The 1-based index of the task that runs the caller (the runtime counts the
      // configuration's tasks in order; a lone program is task 1).
      {"GETCURTASKINDEX",
       "FUNCTION_BLOCK GETCURTASKINDEX\nVAR_OUTPUT index : BYTE; END_VAR\nindex := __TASKINDEX();\nEND_FUNCTION_BLOCK\n",
       nullptr},
      // The CPU counter in 100 ns units. The PLC's counts from some moment at boot; this
      // one is the scan clock (virtual or real), so timings measured with it are the
      // simulated ones and a run repeats.
      {"GETCPUCOUNTER",
       "FUNCTION_BLOCK GETCPUCOUNTER\nVAR_OUTPUT cpuCntLoDW : UDINT; cpuCntHiDW : UDINT; END_VAR\n"
       "VAR ticks : ULINT; END_VAR\n"
       "ticks := LINT_TO_ULINT(TIME_TO_NS(__NOW()) / 100);\n"
       "cpuCntLoDW := ULINT_TO_UDINT(ticks AND 16#FFFFFFFF);\n"
       "cpuCntHiDW := ULINT_TO_UDINT(SHR(ticks, 32));\nEND_FUNCTION_BLOCK\n",
       nullptr},
      // The index of the running task, as a function (TwinCAT's usual way to index _TaskInfo).
      {"GETCURTASKINDEXEX", "FUNCTION GETCURTASKINDEXEX : BYTE\nGETCURTASKINDEXEX := __TASKINDEX();\nEND_FUNCTION\n", nullptr},
      // What the runtime tells a PLC program about its tasks, one entry per task by its
      // index (TwinCAT's TwinCAT_SystemInfoVarList). The scheduler (runtime/schedule.cpp)
      // fills CycleTime, Priority, TaskName, CycleCount and FirstCycle before each cycle
      // of the task; the rest stays 0 (no TcCOM objects, ADS ports or distributed clocks).
      {"PlcTaskSystemInfo",
       "TYPE PlcTaskSystemInfo :\nSTRUCT\n  ObjId : UDINT;\n  CycleTime : UDINT;\n  Priority : UINT;\n  AdsPort : UINT;\n"
       "  CycleCount : UDINT;\n  DcTaskTime : LINT;\n  LastExecTime : UDINT;\n  FirstCycle : BOOL;\n"
       "  CycleTimeExceeded : BOOL;\n  InCallAfterOutputUpdate : BOOL;\n  RTViolation : BOOL;\n  TaskName : STRING(63);\n"
       "END_STRUCT\nEND_TYPE\n",
       nullptr},
      {"_TaskInfo", "VAR_GLOBAL _TaskInfo : ARRAY[1..32] OF PlcTaskSystemInfo; END_VAR\n", "PlcTaskSystemInfo"},
      // Calls the counter FB it is given and joins its two halves, as TcUnit uses it.
      {"F_GetCpuCounterAs64bit",
       "FUNCTION F_GetCpuCounterAs64bit : ULINT\nVAR_IN_OUT fbCpuCounter : GETCPUCOUNTER; END_VAR\n"
       "fbCpuCounter();\n"
       "F_GetCpuCounterAs64bit := SHL(UDINT_TO_ULINT(fbCpuCounter.cpuCntHiDW), 32) OR "
       "UDINT_TO_ULINT(fbCpuCounter.cpuCntLoDW);\nEND_FUNCTION\n",
       "GETCPUCOUNTER"},
  };
  return items;
}

const char* unprovided_library(std::string_view name) {
  // Names TwinCAT projects commonly call from libraries plcfi does not provide: files,
  // ADS communication, the Windows side of the system, motion, EtherCAT diagnostics.
  struct Known {
    const char* name;
    const char* library;
  };
  static constexpr Known kKnown[] = {
      {"FB_FileOpen", "Tc2_System"}, {"FB_FileClose", "Tc2_System"}, {"FB_FileRead", "Tc2_System"},
      {"FB_FileWrite", "Tc2_System"}, {"FB_FileGets", "Tc2_System"}, {"FB_FilePuts", "Tc2_System"},
      {"FB_FileSeek", "Tc2_System"}, {"FB_FileTell", "Tc2_System"}, {"FB_FileDelete", "Tc2_System"},
      {"FB_FileRename", "Tc2_System"}, {"FB_EOF", "Tc2_System"}, {"FB_CreateDir", "Tc2_System"},
      {"FB_RemoveDir", "Tc2_System"}, {"ADSREAD", "Tc2_System"}, {"ADSWRITE", "Tc2_System"},
      {"ADSRDWRT", "Tc2_System"}, {"ADSREADEX", "Tc2_System"}, {"ADSRDWRTEX", "Tc2_System"},
      {"ADSRDSTATE", "Tc2_System"}, {"ADSWRTCTL", "Tc2_System"}, {"ADSRDDEVINFO", "Tc2_System"},
      {"ADSLOGEVENT", "Tc2_System"}, {"GETSYSTEMTIME", "Tc2_System"}, {"GETCPUACCOUNT", "Tc2_System"},
      {"NT_Shutdown", "Tc2_System"}, {"NT_Reboot", "Tc2_System"}, {"NT_StartProcess", "Tc2_System"},
      {"PLC_Start", "Tc2_System"}, {"PLC_Stop", "Tc2_System"}, {"PLC_Reset", "Tc2_System"},
      {"TC_Restart", "Tc2_System"}, {"TC_Stop", "Tc2_System"}, {"FB_SetLedColor", "Tc2_System"},
      {"NT_GetTime", "Tc2_Utilities"}, {"NT_SetLocalTime", "Tc2_Utilities"}, {"FB_LocalSystemTime", "Tc2_Utilities"},
      {"FB_FormatString", "Tc2_Utilities"}, {"FB_GetLocalAmsNetId", "Tc2_Utilities"},
      {"FB_BufferedTextFile", "Tc2_Utilities"}, {"FB_EnumFindFileList", "Tc2_Utilities"},
      {"FB_MemBufferMerge", "Tc2_Utilities"}, {"FB_StringRingBuffer", "Tc2_Utilities"},
      {"F_FormatArgToStr", "Tc2_Utilities"}, {"SYSTEMTIME_TO_STRING", "Tc2_Utilities"},
      // Beremiz's blocks that run Python in the runtime: no IEC code to run.
      {"python_eval", "Beremiz's Python extension (it runs Python code in the runtime)"},
      {"python_poll", "Beremiz's Python extension (it runs Python code in the runtime)"},
      {"python_gear", "Beremiz's Python extension (it runs Python code in the runtime)"},
      {"MC_Power", "Tc2_MC2"}, {"MC_Reset", "Tc2_MC2"}, {"MC_Home", "Tc2_MC2"}, {"MC_Stop", "Tc2_MC2"},
      {"MC_Halt", "Tc2_MC2"}, {"MC_MoveAbsolute", "Tc2_MC2"}, {"MC_MoveRelative", "Tc2_MC2"},
      {"MC_MoveVelocity", "Tc2_MC2"}, {"MC_ReadStatus", "Tc2_MC2"}, {"AXIS_REF", "Tc2_MC2"},
      {"FB_EcCoESdoRead", "Tc2_EtherCAT"}, {"FB_EcCoESdoWrite", "Tc2_EtherCAT"},
      {"FB_EcGetAllSlaveAddr", "Tc2_EtherCAT"}, {"FB_EcGetSlaveCount", "Tc2_EtherCAT"},
  };
  for (const Known& k : kKnown)
    if (iequals(k.name, name)) return k.library;
  return nullptr;
}

}  // namespace plcfi::st
