// Declarations: POUs (programs, functions, function blocks, interfaces, methods, properties),
// VAR blocks, types, and configurations with their resources, tasks and program instances.
#include "parser_impl.hpp"
#include "sfc_lower.hpp"

namespace plcfi::st::detail {

namespace {

TypeSpecPtr error_type(SourceLoc loc) {
  auto t = std::make_unique<TypeSpec>();
  t->kind = TypeSpecKind::Named;
  t->loc = loc;
  t->name = Ident{"<error>", loc};
  return t;
}

}  // namespace

// ================================================================ declarations

// var_block := var_keyword {CONSTANT | RETAIN | NON_RETAIN | PERSISTENT} {var_decl} END_VAR
VarBlock Parser::parse_var_block() {
  const Token& kw = advance();
  VarBlock block;
  block.loc = kw.loc;
  switch (kw.kind) {
    case Tok::VarInput: block.section = VarSection::Input; break;
    case Tok::VarOutput: block.section = VarSection::Output; break;
    case Tok::VarInOut: block.section = VarSection::InOut; break;
    case Tok::VarTemp: block.section = VarSection::Temp; break;
    case Tok::VarGlobal: block.section = VarSection::Global; break;
    case Tok::VarExternal: block.section = VarSection::External; break;
    case Tok::VarStat: block.section = VarSection::Stat; break;
    case Tok::VarInst: block.section = VarSection::Inst; break;
    case Tok::VarConfig: block.section = VarSection::Config; break;
    default: block.section = VarSection::Var; break;
  }
  for (;;) {
    if (accept(Tok::Constant)) block.constant = true;
    else if (accept(Tok::Retain) || accept(Tok::Persistent)) block.retain = true;
    else if (accept(Tok::NonRetain)) block.retain = false;
    else break;
  }
  const std::string opener(kw.text);
  for (;;) {
    if (accept(Tok::EndVar)) {
      accept(Tok::Semi);  // tolerated: `END_VAR;`
      break;
    }
    if (at(Tok::Ident)) {
      const Tok next = la(1).kind;
      const bool stmt_like = next == Tok::Assign || next == Tok::LParen || next == Tok::Caret ||
                             next == Tok::RefAssign ||
                             (block.section != VarSection::Config && (next == Tok::Dot || next == Tok::LBracket));
      if (!stmt_like) {
        const size_t before = pos_;
        parse_var_decl(block.decls, block.section, block.section == VarSection::Config);
        if (pos_ == before) advance();
        continue;
      }
    }
    if (at(Tok::Ident) || at_terminator() || is_stmt_keyword(cur().kind)) {
      Diagnostic* d = error("ST120", cur().loc, "expected END_VAR to close " + opener + " at line " +
                                                    std::to_string(kw.loc.line) + ", found " + describe(cur()));
      if (d) d->notes.emplace_back(kw.loc, opener + " starts here");
      break;
    }
    error("ST121", cur().loc, "expected a variable declaration such as 'x : INT;', found " + describe(cur()));
    const size_t before = pos_;
    sync_decl();
    if (pos_ == before) advance();
  }
  for (auto& d : block.decls) {
    d.section = block.section;
    d.constant = block.constant;
    d.retain = block.retain;
  }
  block.decls.shrink_to_fit();  // the tree lives through compilation: no growth slack
  return block;
}

// var_decl := name {',' name} [AT direct_address] ':' type_spec [':=' initializer] ';'
// (VAR_CONFIG: name is a dotted instance path)
bool Parser::parse_var_decl(std::vector<VarDecl>& out, VarSection section, bool path_names) {
  VarDecl decl;
  decl.section = section;
  decl.loc = cur().loc;
  do {
    Ident name;
    if (!expect_ident(&name, "ST100", "a variable name")) {
      sync_decl();
      return false;
    }
    while (path_names && at(Tok::Dot) && la(1).kind == Tok::Ident) {
      advance();
      name.text += "." + std::string(advance().text);
    }
    decl.names.push_back(std::move(name));
  } while (accept(Tok::Comma));
  if (at(Tok::At)) {
    const Token& at_kw = advance();
    if (at(Tok::DirectAddr)) {
      const Token& t = advance();
      DirectAddrExpr addr(t.loc);
      addr.text = std::string(t.text);
      addr.area = t.area;
      addr.size = t.size;
      addr.parts = t.parts;
      decl.location = std::move(addr);
    } else {
      error("ST123", missing_loc(), "expected a direct address such as %IX0.0 after AT, found " + describe(cur()));
    }
    if (decl.names.size() > 1)
      error("ST123", at_kw.loc, "AT can locate only a single variable, not " + std::to_string(decl.names.size()));
  }
  const std::string first = decl.names.front().text;
  if (!accept(Tok::Colon)) {
    error("ST134", missing_loc(), "expected ':' and a type after '" + first + "', found " + describe(cur()));
    sync_decl();
    return false;
  }
  decl.type = parse_type_spec();
  if (accept(Tok::Assign)) decl.init = parse_initializer();
  if (!accept(Tok::Semi)) {
    error("ST105", missing_loc(), "expected ';' after the declaration of '" + first + "', found " + describe(cur()));
    if (pos_ > 0 && cur().loc.line == prev().end.line && !at(Tok::EndVar) && !at(Tok::EndStruct)) sync_decl();
  }
  out.push_back(std::move(decl));
  return true;
}

// type_spec := ARRAY '[' range {',' range} ']' OF type_spec
//            | STRUCT {var_decl} END_STRUCT | UNION {var_decl} END_UNION
//            | REF_TO type_spec | POINTER TO type_spec | REFERENCE TO type_spec
//            | '(' enum_value {',' enum_value} ')' [name]
//            | (STRING | WSTRING) ['[' expr ']' | '(' expr ')']
//            | name ['(' enum_value {',' enum_value} ')' | '(' expr '..' expr ')' | call_args]
// range := expr '..' expr
TypeSpecPtr Parser::parse_type_spec() {
  DepthGuard guard(*this);
  const Token& t = cur();
  if (guard.exceeded) {
    report_too_deep();
    skip_nested();
    return error_type(t.loc);
  }
  auto spec = std::make_unique<TypeSpec>();
  spec->loc = t.loc;
  if (at(Tok::Array)) {
    advance();
    spec->kind = TypeSpecKind::Array;
    if (expect(Tok::LBracket, "ST119", "after ARRAY")) {
      do {
        TypeSpec::Range r;
        if (at(Tok::Star) && (la(1).kind == Tok::Comma || la(1).kind == Tok::RBracket)) {
          advance();
          r.open = true;
          spec->dims.push_back(std::move(r));
          continue;
        }
        r.lo = parse_expr();
        if (!accept(Tok::DotDot)) {
          error("ST119", missing_loc(), "expected '..' in the array bounds (e.g. ARRAY [1..10] OF INT), found " +
                                            describe(cur()));
        }
        r.hi = parse_expr();
        spec->dims.push_back(std::move(r));
      } while (accept(Tok::Comma));
      expect(Tok::RBracket, "ST116", "to close the array bounds");
    }
    expect(Tok::Of, "ST109", "after the array bounds");
    spec->element = parse_type_spec();
    return spec;
  }
  // UNION is parsed in every dialect; the compiler rejects it under --dialect iec.
  if (at(Tok::Struct) || at_word("UNION")) {
    spec->is_union = !at(Tok::Struct);
    const char* opener = spec->is_union ? "UNION" : "STRUCT";
    const char* closer = spec->is_union ? "END_UNION" : "END_STRUCT";
    advance();
    spec->kind = TypeSpecKind::Struct;
    for (;;) {
      if (spec->is_union ? at_word("END_UNION") : at(Tok::EndStruct)) {
        advance();
        break;
      }
      if (at(Tok::Ident)) {
        const size_t before = pos_;
        parse_var_decl(spec->members, VarSection::Var, false);
        if (pos_ == before) advance();
        continue;
      }
      if (at_terminator() || is_stmt_keyword(cur().kind)) {
        Diagnostic* d = error("ST124", cur().loc, std::string("expected ") + closer + " to close " + opener + " at line " +
                                                      std::to_string(t.loc.line) + ", found " + describe(cur()));
        if (d) d->notes.emplace_back(t.loc, std::string(opener) + " starts here");
        break;
      }
      error("ST121", cur().loc, "expected a member declaration such as 'x : INT;', found " + describe(cur()));
      const size_t before = pos_;
      sync_decl();
      if (pos_ == before) advance();
    }
    return spec;
  }
  // REFERENCE TO is parsed in every dialect; the compiler rejects it under --dialect iec.
  if (at(Tok::RefTo) || ((at_word("POINTER") || at_word("REFERENCE")) && la(1).kind == Tok::To)) {
    spec->is_reference = at_word("REFERENCE");
    spec->is_pointer = !at(Tok::RefTo) && !spec->is_reference;
    const bool two_words = !at(Tok::RefTo);
    advance();
    if (two_words) advance();
    spec->kind = TypeSpecKind::Ref;
    spec->element = parse_type_spec();
    return spec;
  }
  if (at(Tok::LParen)) {
    spec->kind = TypeSpecKind::Enum;
    parse_enum_values(*spec);
    // `(A, B) INT`; but a name followed by ':' starts the next declaration (missing ';').
    if (at(Tok::Ident) && la(1).kind != Tok::Colon && la(1).kind != Tok::Comma) {
      const Token& b = advance();
      spec->element = std::make_unique<TypeSpec>();
      spec->element->loc = b.loc;
      spec->element->name = Ident{std::string(b.text), b.loc};
    }
    return spec;
  }
  if (!at(Tok::Ident)) {
    error("ST119", missing_loc(), "expected a type, found " + describe(cur()));
    return error_type(t.loc);
  }
  advance();
  spec->kind = TypeSpecKind::Named;
  spec->name = Ident{std::string(t.text), t.loc};
  skip_namespace(&spec->name);
  const bool is_string = iequals(t.text, "STRING") || iequals(t.text, "WSTRING");
  if (is_string && (at(Tok::LBracket) || at(Tok::LParen))) {
    const Tok close = at(Tok::LBracket) ? Tok::RBracket : Tok::RParen;
    advance();
    spec->string_length = parse_expr();
    expect(close, "ST116", "to close the string length");
    return spec;
  }
  if (at(Tok::LParen) && !is_integer_type_name(t.text) && !subrange_follows()) {
    // `fb : FB_X(a := 1, 'name')`: FB_init arguments (CODESYS). Typed enumerations and
    // subranges are based on an elementary integer type, so only those take '(' otherwise.
    spec->has_init_args = true;
    parse_call_args(spec->init_args, spec->name.text);
    return spec;
  }
  if (at(Tok::LParen)) {
    const Tok k1 = la(1).kind, k2 = la(2).kind;
    if (k1 == Tok::Ident && (k2 == Tok::Assign || k2 == Tok::Comma || k2 == Tok::RParen)) {
      // Typed enum INT (A := 1, B := 2): the named type becomes the base.
      auto base = std::move(spec);
      spec = std::make_unique<TypeSpec>();
      spec->kind = TypeSpecKind::Enum;
      spec->loc = base->loc;
      parse_enum_values(*spec);
      spec->element = std::move(base);
      return spec;
    }
    advance();
    auto base = std::move(spec);
    spec = std::make_unique<TypeSpec>();
    spec->kind = TypeSpecKind::Subrange;
    spec->loc = base->loc;
    spec->element = std::move(base);
    spec->sub_lo = parse_expr();
    if (!accept(Tok::DotDot))
      error("ST119", missing_loc(), "expected '..' in the subrange (e.g. INT (0..100)), found " + describe(cur()));
    spec->sub_hi = parse_expr();
    expect(Tok::RParen, "ST116", "to close the subrange");
  }
  return spec;
}

// The elementary integer types: the only bases of a typed enumeration or a subrange.
bool Parser::is_integer_type_name(std::string_view name) {
  static constexpr std::string_view kNames[] = {"SINT", "INT",  "DINT", "LINT",  "USINT", "UINT",
                                                "UDINT", "ULINT", "BYTE", "WORD", "DWORD", "LWORD"};
  for (std::string_view n : kNames)
    if (iequals(name, n)) return true;
  return false;
}

// At '(': whether a '..' follows at the first level of the parentheses (a subrange).
bool Parser::subrange_follows() const {
  int depth = 0;
  for (size_t k = 0;; ++k) {
    const Tok kind = la(k).kind;
    if (kind == Tok::Eof || kind == Tok::Semi) return false;
    if (kind == Tok::LParen || kind == Tok::LBracket) ++depth;
    if ((kind == Tok::RParen || kind == Tok::RBracket) && --depth == 0) return false;
    if (kind == Tok::DotDot && depth == 1) return true;
  }
}

// return_type := type_spec   (after FUNCTION name ':' / METHOD name ':')
TypeSpecPtr Parser::parse_return_type() {
  // `FUNCTION F :` with the type forgotten: do not take the first statement's target as the type.
  if (at(Tok::Ident) && (la(1).kind == Tok::Assign || la(1).kind == Tok::RefAssign)) {
    error("ST119", missing_loc(), "expected the return type after ':', found " + describe(cur()));
    return error_type(cur().loc);
  }
  return parse_type_spec();
}

// enum_values := '(' enum_value {',' enum_value} ')'; enum_value := name [':=' expr]
void Parser::parse_enum_values(TypeSpec& spec) {
  advance();  // '('
  do {
    TypeSpec::EnumValue v;
    if (!expect_ident(&v.name, "ST119", "an enumeration value name")) break;
    if (accept(Tok::Assign)) v.value = parse_expr();
    spec.enum_values.push_back(std::move(v));
  } while (accept(Tok::Comma));
  expect(Tok::RParen, "ST116", "to close the enumeration");
}

// type_block := TYPE type_decl {type_decl} END_TYPE
// type_decl := name ':' type_spec [':=' initializer] ';'   (';' optional after END_STRUCT)
void Parser::parse_type_block(std::vector<TypeDecl>& out) {
  const Token& kw = advance();
  FrameGuard frame(*this, {Tok::EndType, Tok::Eof, Tok::Eof}, false);
  for (;;) {
    if (accept(Tok::EndType)) {
      accept(Tok::Semi);
      return;
    }
    if (at(Tok::Ident)) {
      TypeDecl td;
      const Token& name = advance();
      td.name = Ident{std::string(name.text), name.loc};
      td.loc = name.loc;
      std::optional<Ident> base;
      if (accept(Tok::Extends)) {  // CODESYS: TYPE T EXTENDS B : STRUCT ... END_STRUCT
        Ident b;
        if (expect_ident(&b, "ST100", "a base STRUCT name after EXTENDS")) {
          skip_namespace(&b);
          base = b;
        }
      }
      if (!accept(Tok::Colon)) {
        error("ST134", missing_loc(), "expected ':' and a type after '" + td.name.text + "', found " + describe(cur()));
        sync_decl();
        continue;
      }
      td.spec = parse_type_spec();
      if (base) {
        if (td.spec->kind == TypeSpecKind::Struct && !td.spec->is_union)
          td.spec->struct_base = *base;
        else
          error("ST119", base->loc, "only a STRUCT can EXTEND another ('" + td.name.text + "' is not a STRUCT)");
      }
      if (accept(Tok::Assign)) td.init = parse_initializer();
      const bool struct_like = td.spec->kind == TypeSpecKind::Struct;
      if (!accept(Tok::Semi) && !struct_like) {
        error("ST105", missing_loc(), "expected ';' after the type declaration of '" + td.name.text + "', found " +
                                          describe(cur()));
        if (pos_ > 0 && cur().loc.line == prev().end.line && !at(Tok::EndType)) sync_decl();
      }
      out.push_back(std::move(td));
      continue;
    }
    if (at_terminator() || is_stmt_keyword(cur().kind)) {
      Diagnostic* d = error("ST126", cur().loc, "expected END_TYPE to close TYPE at line " +
                                                    std::to_string(kw.loc.line) + ", found " + describe(cur()));
      if (d) d->notes.emplace_back(kw.loc, "TYPE starts here");
      return;
    }
    error("ST126", cur().loc, "expected a type declaration such as 'MyInt : INT;', found " + describe(cur()));
    const size_t before = pos_;
    sync_decl();
    if (pos_ == before) advance();
  }
}

// modifiers := {PUBLIC | PRIVATE | PROTECTED | INTERNAL | ABSTRACT | FINAL | OVERRIDE}
// (contextual words: only taken as modifiers when a name follows)
void Parser::parse_modifiers(Access* access, bool* is_abstract, bool* is_final) {
  while (at(Tok::Ident) && la(1).kind == Tok::Ident) {
    const std::string w = canon(cur().text);
    if (w == "PUBLIC") *access = Access::Public;
    else if (w == "PRIVATE") *access = Access::Private;
    else if (w == "PROTECTED") *access = Access::Protected;
    else if (w == "INTERNAL") *access = Access::Internal;
    else if (w == "ABSTRACT") *is_abstract = true;
    else if (w == "FINAL") *is_final = true;
    else if (w == "OVERRIDE") {
    } else {
      return;
    }
    advance();
  }
}

void Parser::expect_unit_end(Tok end, const std::string& what, SourceLoc open_loc, SourceLoc* end_loc) {
  if (at(end)) {
    *end_loc = advance().loc;
    accept(Tok::Semi);
    return;
  }
  *end_loc = cur().loc;
  if (is_unit_end(cur().kind) && !open_has(cur().kind)) {
    Diagnostic* d = error("ST102", cur().loc, describe(cur()) + " does not match " + what + " (line " +
                                                  std::to_string(open_loc.line) + "): expected " +
                                                  std::string(tok_name(end)), true);
    if (d) d->notes.emplace_back(open_loc, what + " starts here");
    advance();
    accept(Tok::Semi);
    return;
  }
  Diagnostic* d = error("ST103", cur().loc, "expected " + std::string(tok_name(end)) + " to close " + what +
                                                " (line " + std::to_string(open_loc.line) + "), found " +
                                                describe(cur()), true);
  if (d) d->notes.emplace_back(open_loc, what + " starts here");
}

// pou_body := {var_block | method | property | statement}
void Parser::parse_pou_body(Pou& pou, bool allow_members) {
  bool seen_statements = false;
  for (;;) {
    const size_t before = pos_;
    if (is_var_keyword(cur().kind)) {
      if (seen_statements)
        error("ST129", cur().loc, "variable declarations must come before the statements of " +
                                      std::string(pou_keyword(pou.kind)) + " '" + pou.name.text + "'");
      if (at(Tok::VarInst) && pou.kind != PouKind::Method)
        error("ST129", cur().loc, "VAR_INST is only allowed in a METHOD (a variable of the method kept in its "
                                  "function block's instance), not in " + std::string(pou_keyword(pou.kind)) + " '" +
                                  pou.name.text + "'");
      pou.var_blocks.push_back(parse_var_block());
    } else if (at(Tok::Method) || at(Tok::Property)) {
      if (!allow_members) {
        error("ST129", cur().loc, std::string(tok_name(cur().kind)) + " is not allowed inside " +
                                      pou_keyword(pou.kind) + " '" + pou.name.text +
                                      "' (only in FUNCTION_BLOCK, PROGRAM and INTERFACE)");
        if (pou.kind == PouKind::Method) return;  // probably a missing END_METHOD
      }
      const bool in_interface = pou.kind == PouKind::Interface;
      if (at(Tok::Method)) pou.methods.push_back(parse_method(in_interface));
      else pou.properties.push_back(parse_property(in_interface));
    } else if (at(Tok::Eof) || is_unit_end(cur().kind) || is_top_level_start(cur().kind) || at(Tok::Resource) ||
               at_test_block_start()) {
      return;
    } else if (at_sfc_start()) {
      parse_sfc_element(pou);
      seen_statements = true;
    } else if (!seen_statements && pou.has_body && pou.kind != PouKind::Interface && at_il_body()) {
      parse_il_body(pou);
      seen_statements = true;
    } else {
      const size_t first = pou.body.size();
      parse_stmt_list(pou.body, false);
      if (pou.body.size() > first && pou.sfc)
        error("ST141", pou.body[first]->loc, std::string(pou_keyword(pou.kind)) + " '" + pou.name.text +
                                                 "' mixes SFC elements and ST statements: its body is either a chart "
                                                 "or a statement list (put the statements into an ACTION)", true);
      if (pou.body.size() > first) {
        seen_statements = true;
        if (pou.kind == PouKind::Interface || !pou.has_body)
          error("ST129", pou.body[first]->loc, std::string(pou.kind == PouKind::Interface ? "an INTERFACE" : "a method prototype") +
                                                   " cannot contain statements");
      }
    }
    if (pos_ == before) return;
  }
}

// pou := PROGRAM name pou_body END_PROGRAM
//      | FUNCTION name [':' type_spec] pou_body END_FUNCTION
//      | FUNCTION_BLOCK {ABSTRACT | FINAL | access} name [EXTENDS name] [IMPLEMENTS name {',' name}]
//        pou_body END_FUNCTION_BLOCK
//      | INTERFACE name [EXTENDS name {',' name}] pou_body END_INTERFACE
PouPtr Parser::parse_pou() {
  const Token& kw = advance();
  auto pou = std::make_unique<Pou>();
  pou->loc = kw.loc;
  Tok end = Tok::EndProgram;
  switch (kw.kind) {
    case Tok::Function: pou->kind = PouKind::Function; end = Tok::EndFunction; break;
    case Tok::FunctionBlock: pou->kind = PouKind::FunctionBlock; end = Tok::EndFunctionBlock; break;
    case Tok::Interface: pou->kind = PouKind::Interface; end = Tok::EndInterface; break;
    default: pou->kind = PouKind::Program; break;
  }
  FrameGuard frame(*this, {end, Tok::Eof, Tok::Eof}, false);
  if (pou->kind == PouKind::FunctionBlock) parse_modifiers(&pou->access, &pou->is_abstract, &pou->is_final);
  expect_ident(&pou->name, "ST100", std::string("a name after ") + std::string(kw.text));
  if (pou->kind == PouKind::Function && accept(Tok::Colon)) pou->return_type = parse_return_type();
  if (pou->kind == PouKind::FunctionBlock) {
    if (accept(Tok::Extends)) {
      Ident base;
      if (expect_ident(&base, "ST100", "a base FUNCTION_BLOCK name after EXTENDS")) {
        skip_namespace(&base);
        pou->extends = base;
      }
    }
    if (accept(Tok::Implements)) {
      do {
        Ident i;
        if (!expect_ident(&i, "ST100", "an interface name after IMPLEMENTS")) break;
        skip_namespace(&i);
        pou->implements.push_back(std::move(i));
      } while (accept(Tok::Comma));
    }
  } else if (pou->kind == PouKind::Interface && accept(Tok::Extends)) {
    do {
      Ident i;
      if (!expect_ident(&i, "ST100", "an interface name after EXTENDS")) break;
      skip_namespace(&i);
      pou->implements.push_back(std::move(i));
    } while (accept(Tok::Comma));
  }
  if (pou->kind == PouKind::Interface) pou->has_body = false;
  accept(Tok::Semi);  // tolerated after the header
  parse_pou_body(*pou, pou->kind != PouKind::Function);
  const std::string what = std::string(pou_keyword(pou->kind)) + " '" + pou->name.text + "'";
  expect_unit_end(end, what, kw.loc, &pou->end_loc);
  if (pou->sfc) lower_sfc(*pou, diags_);
  return pou;
}

// method := METHOD {access | ABSTRACT | FINAL | OVERRIDE} name [':' type_spec] {var_block} stmt_list END_METHOD
PouPtr Parser::parse_method(bool in_interface) {
  const Token& kw = advance();
  auto m = std::make_unique<Pou>();
  m->kind = PouKind::Method;
  m->loc = kw.loc;
  m->has_body = !in_interface;
  FrameGuard frame(*this, {Tok::EndMethod, Tok::Eof, Tok::Eof}, false);
  parse_modifiers(&m->access, &m->is_abstract, &m->is_final);
  expect_ident(&m->name, "ST100", "a method name after METHOD");
  if (accept(Tok::Colon)) m->return_type = parse_return_type();
  accept(Tok::Semi);
  parse_pou_body(*m, false);
  expect_unit_end(Tok::EndMethod, "METHOD '" + m->name.text + "'", kw.loc, &m->end_loc);
  return m;
}

// property := PROPERTY {access | ABSTRACT | FINAL | OVERRIDE} name ':' type_spec {accessor} END_PROPERTY
// accessor := GET {var_block} stmt_list END_GET | SET {var_block} stmt_list END_SET
std::unique_ptr<PropertyDecl> Parser::parse_property(bool in_interface) {
  const Token& kw = advance();
  auto p = std::make_unique<PropertyDecl>();
  p->loc = kw.loc;
  FrameGuard frame(*this, {Tok::EndProperty, Tok::Eof, Tok::Eof}, false);
  bool is_abstract = false, is_final = false;
  parse_modifiers(&p->access, &is_abstract, &is_final);
  expect_ident(&p->name, "ST100", "a property name after PROPERTY");
  if (accept(Tok::Colon)) {
    p->type = parse_type_spec();
  } else {
    error("ST134", missing_loc(), "expected ':' and a type after PROPERTY '" + p->name.text + "', found " +
                                      describe(cur()));
    p->type = error_type(cur().loc);
  }
  accept(Tok::Semi);
  for (;;) {
    const bool get = at_word("GET");
    if (!get && !at_word("SET")) break;
    const Token& acc = advance();
    auto a = std::make_unique<Pou>();
    a->kind = PouKind::Method;
    a->name = p->name;
    a->loc = acc.loc;
    a->access = p->access;
    a->is_abstract = is_abstract;
    a->is_final = is_final;
    a->has_body = !in_interface;
    const Tok end = get ? Tok::EndGet : Tok::EndSet;
    {
      FrameGuard acc_frame(*this, {end, Tok::Eof, Tok::Eof}, false);
      parse_pou_body(*a, false);
      expect_unit_end(end, std::string(get ? "GET" : "SET") + " of PROPERTY '" + p->name.text + "'", acc.loc,
                      &a->end_loc);
    }
    if (get ? p->getter != nullptr : p->setter != nullptr)
      error("ST129", acc.loc, std::string("duplicate ") + (get ? "GET" : "SET") + " in PROPERTY '" + p->name.text + "'");
    (get ? p->getter : p->setter) = std::move(a);
  }
  if (!at(Tok::EndProperty) && !is_unit_end(cur().kind) && !at(Tok::Eof) && !is_top_level_start(cur().kind) &&
      !at(Tok::Method) && !at(Tok::Property)) {
    error("ST100", cur().loc, "expected GET, SET or END_PROPERTY in PROPERTY '" + p->name.text + "', found " +
                                  describe(cur()));
    // Skip to the end of the property rather than misreading its contents.
    while (!at(Tok::Eof) && !at(Tok::EndProperty) && !is_top_level_start(cur().kind) &&
           !(is_unit_end(cur().kind) && open_has(cur().kind) && !at(Tok::EndProperty)))
      advance();
  }
  SourceLoc end_loc;
  expect_unit_end(Tok::EndProperty, "PROPERTY '" + p->name.text + "'", kw.loc, &end_loc);
  return p;
}

// task := TASK name '(' name ':=' expr {',' name ':=' expr} ')' ';'
TaskDecl Parser::parse_task() {
  const Token& kw = advance();
  TaskDecl task;
  task.loc = kw.loc;
  expect_ident(&task.name, "ST100", "a task name after TASK");
  if (accept(Tok::LParen)) {
    if (!at(Tok::RParen)) {
      do {
        Ident param;
        if (!expect_ident(&param, "ST128", "a task parameter (INTERVAL, PRIORITY or SINGLE)")) break;
        expect(Tok::Assign, "ST128", "after task parameter '" + param.text + "'");
        ExprPtr value = parse_expr();
        const std::string w = canon(param.text);
        if (w == "INTERVAL") task.interval = std::move(value);
        else if (w == "PRIORITY") task.priority = std::move(value);
        else if (w == "SINGLE") task.single = std::move(value);
        else
          error("ST128", param.loc, "unknown task parameter '" + param.text + "' (expected INTERVAL, PRIORITY or SINGLE)");
      } while (accept(Tok::Comma));
    }
    expect(Tok::RParen, "ST116", "to close the task parameters");
  }
  expect_semi("the TASK declaration");
  return task;
}

// program_inst := PROGRAM name [WITH name] ':' name ['(' call_args ')'] ';'
ProgramInstDecl Parser::parse_program_inst() {
  const Token& kw = advance();
  ProgramInstDecl p;
  p.loc = kw.loc;
  expect_ident(&p.instance, "ST100", "a program instance name after PROGRAM");
  if (at_word("WITH")) {
    advance();
    Ident task;
    if (expect_ident(&task, "ST100", "a task name after WITH")) p.task = task;
  }
  if (expect(Tok::Colon, "ST127", "and the program type after the instance name '" + p.instance.text + "'"))
    expect_ident(&p.type, "ST100", "a program type name");
  if (at(Tok::LParen)) parse_call_args(p.args, p.instance.text);
  expect_semi("the PROGRAM instance declaration");
  return p;
}

// resource_body := {var_block | task | program_inst}
void Parser::parse_resource_body(ResourceDecl& res, Tok end) {
  for (;;) {
    const size_t before = pos_;
    if (at(end) || at(Tok::EndConfiguration) || at(Tok::EndResource) || at(Tok::Eof)) return;
    if (at(Tok::VarGlobal) || at(Tok::VarConfig) || at(Tok::Var)) {
      res.globals.push_back(parse_var_block());
    } else if (at_word("TASK") && la(1).kind == Tok::Ident) {
      res.tasks.push_back(parse_task());
    } else if (at(Tok::Program) && la(1).kind == Tok::Ident && la(2).kind != Tok::Semi &&
               (la(2).kind == Tok::Colon || (la(2).kind == Tok::Ident && iequals(la(2).text, "WITH")))) {
      res.programs.push_back(parse_program_inst());
    } else if (at(Tok::Resource) || is_top_level_start(cur().kind) || is_unit_end(cur().kind)) {
      return;
    } else {
      error("ST127", cur().loc, "expected TASK, PROGRAM, VAR_GLOBAL or " + std::string(tok_name(end)) + ", found " +
                                    describe(cur()));
      sync_decl();
    }
    if (pos_ == before) advance();
  }
}

// configuration := CONFIGURATION name {var_block} {resource | task | program_inst} END_CONFIGURATION
// resource := RESOURCE name ON name {var_block | task | program_inst} END_RESOURCE
ConfigDecl Parser::parse_configuration() {
  const Token& kw = advance();
  ConfigDecl cfg;
  cfg.loc = kw.loc;
  FrameGuard frame(*this, {Tok::EndConfiguration, Tok::Eof, Tok::Eof}, false);
  expect_ident(&cfg.name, "ST100", "a configuration name after CONFIGURATION");
  for (;;) {
    const size_t before = pos_;
    if (at(Tok::EndConfiguration) || at(Tok::Eof)) break;
    if (at(Tok::VarGlobal) || at(Tok::VarConfig) || at(Tok::Var)) {
      cfg.globals.push_back(parse_var_block());
    } else if (at(Tok::Resource)) {
      const Token& rk = advance();
      ResourceDecl res;
      res.loc = rk.loc;
      FrameGuard res_frame(*this, {Tok::EndResource, Tok::Eof, Tok::Eof}, false);
      expect_ident(&res.name, "ST100", "a resource name after RESOURCE");
      if (at_word("ON")) {
        advance();
        expect_ident(&res.on, "ST100", "a processor name after ON");
      } else {
        error("ST127", missing_loc(), "expected ON after RESOURCE '" + res.name.text + "', found " + describe(cur()));
      }
      parse_resource_body(res, Tok::EndResource);
      SourceLoc end_loc;
      expect_unit_end(Tok::EndResource, "RESOURCE '" + res.name.text + "'", rk.loc, &end_loc);
      cfg.resources.push_back(std::move(res));
    } else if ((at_word("TASK") && la(1).kind == Tok::Ident) || at(Tok::Program)) {
      // Tasks and programs directly in the configuration live in an implicit resource.
      if (cfg.resources.empty() || !cfg.resources.back().name.text.empty()) {
        ResourceDecl implicit;
        implicit.loc = cur().loc;
        implicit.name = Ident{"", cur().loc};
        cfg.resources.push_back(std::move(implicit));
      }
      parse_resource_body(cfg.resources.back(), Tok::EndConfiguration);
    } else if (is_top_level_start(cur().kind) || is_unit_end(cur().kind)) {
      break;
    } else {
      error("ST127", cur().loc, "expected RESOURCE, TASK, PROGRAM, VAR_GLOBAL or END_CONFIGURATION, found " +
                                    describe(cur()));
      sync_decl();
    }
    if (pos_ == before) advance();
  }
  SourceLoc end_loc;
  expect_unit_end(Tok::EndConfiguration, "CONFIGURATION '" + cfg.name.text + "'", kw.loc, &end_loc);
  return cfg;
}

// top_level := pou | type_block | var_block | configuration
void Parser::parse_top_level(CompilationUnit& unit) {
  const Tok k = cur().kind;
  if (k == Tok::Program || k == Tok::Function || k == Tok::FunctionBlock || k == Tok::Interface) {
    unit.pous.push_back(parse_pou());
  } else if (k == Tok::Type) {
    parse_type_block(unit.types);
  } else if (is_var_keyword(k)) {
    if (k != Tok::VarGlobal && k != Tok::VarConfig)
      error("ST101", cur().loc, describe(cur()) + " is not allowed at top level (only VAR_GLOBAL)");
    unit.globals.push_back(parse_var_block());
  } else if (k == Tok::Configuration) {
    unit.configs.push_back(parse_configuration());
  } else {
    error("ST101", cur().loc, std::string("expected PROGRAM, FUNCTION_BLOCK, FUNCTION, INTERFACE, TYPE, VAR_GLOBAL") +
                                  (test_mode_ ? ", CONFIGURATION, SETUP, TEARDOWN or TEST" : " or CONFIGURATION") +
                                  ", found " + describe(cur()));
    // One error for a run of garbage: skip to the next declaration.
    advance();
    while (!at(Tok::Eof) && !is_top_level_start(cur().kind) && !at(Tok::VarGlobal) && !at_test_block_start())
      advance();
  }
}

}  // namespace plcfi::st::detail
