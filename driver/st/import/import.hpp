// Importers: project files (PLCopen XML, TwinCAT 3 PLC projects) become source units of
// the one ST front end. Each unit is generated ST text whose lines carry their origin
// (SourceManager::add_generated), so a diagnostic in an imported POU points at the line
// of the .xml or .TcPOU file it came from.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "syntax/diag.hpp"
#include "codegen/compiler.hpp"
#include "syntax/source.hpp"

namespace plcfi::st {

enum class InputKind {
  St,          // plain ST text (.st and anything not below)
  PlcopenXml,  // PLCopen TC6 XML (.xml)
  TwinCat,     // TwinCAT 3: .plcproj, .TcPOU, .TcDUT, .TcGVL, .TcIO, .TcTTO
};
InputKind input_kind(std::string_view path);

// The files of a library given as sources in the folder `dir` (--library DIR), in sorted
// order: the TwinCAT projects (.plcproj) under it when there are any (a library saved as
// a PLC project: the objects the project lists), else every ST source (.st), TwinCAT
// object (.TcPOU, .TcDUT, .TcGVL, .TcIO, .TcTTO) and PLCopen XML file (.xml) under it.
// Folders are searched recursively; hidden ones (.git) are skipped. False, with the reason
// in *err (naming `dir`), when dir does not exist, is not a folder or holds no sources.
bool library_sources(const std::string& dir, std::vector<std::string>* files, std::string* err);

// Reads one project file: loads it into `sm`, adds the ST units it holds (add_generated,
// with line origins in that file) and appends their file indexes to `units`. Problems of
// the file itself (not well-formed XML, a POU body in LD, a listed file that is missing)
// are reported through `diags` at their place in that file. Returns false when any error
// was reported; the units added so far stay in `units`.
bool import_plcopen(const std::string& path, SourceManager& sm, DiagEngine& diags, std::vector<uint32_t>* units);
// A TwinCAT project's library parameters (<PlaceholderReference> <Parameters> <Parameter
// ListName="GVL_PARAM_TCUNIT"><Key>..</Key><Value>..</Value>) are appended to `params`.
bool import_twincat(const std::string& path, SourceManager& sm, DiagEngine& diags, std::vector<uint32_t>* units,
                    std::vector<LibraryParam>* params = nullptr);

}  // namespace plcfi::st
