#include <map>
#include <set>

#include "cohort/scene/material_file.h"
#include "ascii_case.h"

namespace cohort::scene {

namespace {

std::string at(const std::string& file, int line) { return file + ":" + std::to_string(line) + ": "; }

StageBlend gl_blend_pair(Lexer& lex, const Token& src_token) {
  lex.expect(",");
  Token dst_token = lex.expect_any("a destination blend factor");
  std::string src = lowercase(src_token.text), dst = lowercase(dst_token.text);
  if (dst.rfind("gl_", 0) != 0) lex.fail(dst_token, "unknown blend factor '" + dst_token.text + "'");
  if (src == "gl_one" && dst == "gl_zero") return StageBlend::Replace;
  if (src == "gl_zero" && dst == "gl_one") return StageBlend::None;
  if ((src == "gl_dst_color" && dst == "gl_zero") || (src == "gl_zero" && dst == "gl_src_color"))
    return StageBlend::Modulate;
  if (dst == "gl_one") return StageBlend::Add;   // (one, one), (src_alpha, one), (dst_color, one): adds light
  return StageBlend::AlphaBlend;
}

const std::set<std::string>& ignored_stage_words() {
  static const std::set<std::string> words = {
      "maskred", "maskgreen", "maskblue", "maskalpha", "maskcolor", "maskdepth", "ignorealphatest",
      "nearest", "linear", "clamp", "zeroclamp", "alphazeroclamp", "noclamp", "uncompressed", "highquality",
      "forcehighquality", "nopicmip", "ignoredepth"};
  return words;
}

const std::set<std::string>& ignored_material_words() {
  static const std::set<std::string> words = {
      "mirror", "forceoverlays", "forceopaque", "forceshadows", "noportalfog",
      "unsmoothedtangents", "discrete", "nofragment", "noimpact", "nooverlays", "playerclip", "monsterclip",
      "moveableclip", "ikclip", "blood", "trigger", "aassolid", "aasobstacle", "flashlight_trigger",
      "nullnormal", "areaportal", "qer_nocarve", "collision", "nodamage", "solid", "water", "clamp", "zeroclamp",
      "alphazeroclamp", "ladder", "nosteps", "nofog", "metal", "stone", "flesh", "wood", "cardboard", "liquid",
      "glass", "plastic", "ricochet", "surftype10", "surftype11", "surftype12", "surftype13", "surftype14",
      "surftype15", "lightfalloffimage_none", "isolatedsurface", "nodecal"};
  return words;
}

const std::set<std::string>& rest_of_line_material_words() {
  static const std::set<std::string> words = {"qer_editorimage", "sort", "polygonoffset", "spectrum", "renderbump",
                                              "deform", "guisurf", "decalinfo", "materialtype", "qer_trans",
                                              "lightcolor", "portalsky"};
  return words;
}

// Global keywords that only switch a flag of the declaration on.
const std::map<std::string, bool MaterialDecl::*>& material_flag_words() {
  static const std::map<std::string, bool MaterialDecl::*> words = {
      {"translucent", &MaterialDecl::translucent},
      {"noshadows", &MaterialDecl::no_shadows},
      {"twosided", &MaterialDecl::two_sided},
      {"nonsolid", &MaterialDecl::nonsolid},
      {"noselfshadow", &MaterialDecl::no_self_shadow},
      {"decal_macro", &MaterialDecl::no_shadows},  // the macro: polygonOffset, discrete, sort decal, noShadows
      {"foglight", &MaterialDecl::fog_light},
      {"blendlight", &MaterialDecl::blend_light},
      {"ambientlight", &MaterialDecl::ambient_light}};
  return words;
}

const std::set<std::string>& skipped_decl_types() {
  static const std::set<std::string> types = {"skin", "particle", "fx", "entitydef", "sound", "mapdef",
                                              "articulatedfigure", "pda", "email", "video", "audio", "model",
                                              "af", "export", "camera"};
  return types;
}

class MaterialReader {
 public:
  MaterialReader(const std::string& file, MaterialTables& tables, std::vector<std::string>& warnings)
      : file_(file), tables_(tables), warnings_(warnings) {}

  void read_body(Lexer& lex, MaterialDecl& m) {
    ExpressionContext context;
    context.tables = &tables_;
    
    while (!lex.at_end()) {
      Token t = lex.next();
      std::string word = lowercase(t.text);
      if (t.is("{")) {
        read_stage(lex, t, m, context);
      } else if (word == "diffusemap" || word == "bumpmap" || word == "specularmap") {
        MaterialStage stage;
        stage.line = t.line;
        stage.role = word == "diffusemap" ? StageRole::Diffuse : word == "bumpmap" ? StageRole::Bump : StageRole::Specular;
        stage.image = parse_image_program(lex);
        m.stages.push_back(std::move(stage));
      } else if (auto flag = material_flag_words().find(word); flag != material_flag_words().end()) {
        m.*flag->second = true;
      } else if (word == "lightfalloffimage") {
        m.falloff_image = parse_image_program(lex);
      } else if (word == "description") {
        m.description = lex.expect_string("a description");
      } else if (rest_of_line_material_words().count(word)) {
        lex.skip_rest_of_line();
      } else if (ignored_material_words().count(word)) {
      } else {
        warnings_.push_back(at(file_, t.line) + "material " + m.name + ": unknown keyword '" + t.text + "' skipped");
        lex.skip_rest_of_line();
      }
    }
  }

 private:
  void read_stage(Lexer& outer, const Token& open, MaterialDecl& m, ExpressionContext& context) {
    std::string_view body = outer.braced_block_text(open);
    Lexer lex(body, file_, open.line, open.column + 1);
    MaterialStage stage;
    stage.line = open.line;
    try {
      while (!lex.at_end()) read_stage_keyword(lex, stage, m, context);
    } catch (const ParseError& e) {
      warnings_.push_back(std::string(e.what()) + " (stage of material " + m.name + " dropped)");
      return;
    }
    const RegisterInputs at_load;
    for (int c = 0; c < 4; ++c) stage.color[c] = stage.registers.color[c].evaluate(at_load);
    stage.alpha_test = stage.registers.alpha_test;
    stage.alpha_ref = stage.registers.alpha_ref.evaluate(at_load);
    compose_texture_matrix(stage.registers.tex_ops, at_load, stage.tex_transform);
    m.stages.push_back(std::move(stage));
  }

  void read_stage_keyword(Lexer& lex, MaterialStage& stage, const MaterialDecl& m, ExpressionContext& context) {
    Token t = lex.next();
    std::string word = lowercase(t.text);
    if (word == "blend") {
      Token mode = lex.expect_any("a blend mode");
      std::string b = lowercase(mode.text);
      if (b == "diffusemap") stage.role = StageRole::Diffuse;
      else if (b == "bumpmap") stage.role = StageRole::Bump;
      else if (b == "specularmap") stage.role = StageRole::Specular;
      else if (b == "blend") stage.blend = StageBlend::AlphaBlend;
      else if (b == "add") stage.blend = StageBlend::Add;
      else if (b == "filter" || b == "modulate") stage.blend = StageBlend::Modulate;
      else if (b == "none") stage.blend = StageBlend::None;
      else if (b.rfind("gl_", 0) == 0) stage.blend = gl_blend_pair(lex, mode);
      else lex.fail(mode, "unknown blend mode '" + mode.text + "'");
    } else if (word == "map") {
      stage.image = parse_image_program(lex);
    } else if (word == "cubemap" || word == "cameracubemap") {
      stage.special_map = t.text;
      stage.cube_kind = word == "cubemap" ? CubeMapKind::Axis : CubeMapKind::Camera;
      ImageProgram program = parse_image_program(lex);
      if (!program.function.empty())
        warnings_.push_back(at(file_, t.line) + "material " + m.name + ": " + t.text +
                            " of an image program: only its first image's faces are loaded");
      while (!program.function.empty() && !program.inputs.empty()) program = program.inputs.front();
      stage.cube_map = program.path;
    } else if (word == "texgen") {
      read_texgen(lex, stage, m, context);
    } else if (word == "videomap" || word == "soundmap" ||
               word == "mirrorrendermap" || word == "remoterendermap" || word == "xrayrendermap" ||
               word == "fragmentprogram" || word == "vertexprogram" || word == "program" || word == "megatexture") {
      stage.special_map = t.text;
      lex.skip_rest_of_line();
    } else if (word == "vertexparm" || word == "fragmentmap" || word == "privatepolygonoffset") {
      lex.skip_rest_of_line();
    } else if (word == "alphatest") {
      stage.registers.alpha_test = true;
      stage.registers.alpha_ref = parse_expression(lex, context);
    } else if (word == "vertexcolor" || word == "inversevertexcolor") {
      // The engine keeps one vertex-colour mode per stage: the keyword written last wins.
      stage.inverse_vertex_color = word == "inversevertexcolor";
      stage.vertex_color = !stage.inverse_vertex_color;
    } else if (word == "red" || word == "green" || word == "blue" || word == "alpha") {
      int c = word == "red" ? 0 : word == "green" ? 1 : word == "blue" ? 2 : 3;
      stage.registers.color[c] = parse_expression(lex, context);
    } else if (word == "rgb") {
      Expression v = parse_expression(lex, context);
      for (int c = 0; c < 3; ++c) stage.registers.color[c] = v;
    } else if (word == "rgba") {
      Expression v = parse_expression(lex, context);
      for (int c = 0; c < 4; ++c) stage.registers.color[c] = v;
    } else if (word == "colored") {   // the entity's (or light's) colour: parm0-3
      for (int c = 0; c < 4; ++c) stage.registers.color[c] = Expression::parm(c);
    } else if (word == "color") {
      for (int c = 0; c < 4; ++c) {
        if (c > 0) lex.expect(",");
        stage.registers.color[c] = parse_expression(lex, context);
      }
    } else if (word == "scale" || word == "centerscale" || word == "scroll" || word == "translate" ||
               word == "shear") {
      TextureOp op;
      op.kind = word == "scale"         ? TextureOp::Kind::Scale
                : word == "centerscale" ? TextureOp::Kind::CenterScale
                : word == "shear"       ? TextureOp::Kind::Shear
                                        : TextureOp::Kind::Translate;
      op.a = parse_expression(lex, context);
      lex.expect(",");
      op.b = parse_expression(lex, context);
      stage.registers.tex_ops.push_back(std::move(op));
    } else if (word == "rotate") {
      TextureOp op;
      op.kind = TextureOp::Kind::Rotate;
      op.a = parse_expression(lex, context);   // the engine's rotate is in full turns
      stage.registers.tex_ops.push_back(std::move(op));
    } else if (word == "if") {
      parse_expression(lex, context);   // conditions are evaluated per frame by the engine; the stage is kept
    } else if (ignored_stage_words().count(word)) {
    } else {
      warnings_.push_back(at(file_, t.line) + "material " + m.name + ": unknown stage keyword '" + t.text + "' skipped");
      lex.skip_rest_of_line();
    }
  }

  // texgen skybox | wobbleSky a b c | normal | reflect | screen | screen2 | glassWarp (Material.cpp ParseStage).
  void read_texgen(Lexer& lex, MaterialStage& stage, const MaterialDecl& m, ExpressionContext& context) {
    Token kind = lex.expect_any("a texgen kind");
    std::string k = lowercase(kind.text);
    if (k == "skybox") {
      stage.texgen = TexGen::Skybox;
    } else if (k == "wobblesky") {
      stage.texgen = TexGen::WobbleSky;
      const RegisterInputs at_load;
      stage.registers.wobble_sky.clear();
      for (float& value : stage.wobble_sky) {
        stage.registers.wobble_sky.push_back(parse_expression(lex, context));
        value = stage.registers.wobble_sky.back().evaluate(at_load);
      }
    } else if (k == "normal") {
      stage.texgen = TexGen::Normal;
    } else if (k == "reflect") {
      stage.texgen = TexGen::Reflect;
    } else if (k == "screen" || k == "screen2" || k == "glasswarp") {
      stage.texgen = TexGen::Screen;
    } else {
      warnings_.push_back(at(file_, kind.line) + "material " + m.name + ": unknown texgen '" + kind.text + "' skipped");
    }
  }

  const std::string& file_;
  MaterialTables& tables_;
  std::vector<std::string>& warnings_;
};

}  // namespace

MaterialFile parse_materials(std::string_view text, const std::string& file_name, MaterialTables& tables) {
  Lexer lex(text, file_name);
  MaterialFile out;
  MaterialReader reader(file_name, tables, out.warnings);
  while (!lex.at_end()) {
    Token t = lex.next();
    std::string word = lowercase(t.text);
    if (t.kind == Token::Kind::Punct) {
      if (t.text == "{") {
        out.warnings.push_back(at(file_name, t.line) + "a block without a name skipped");
        lex.skip_braced_block();
      } else {
        out.warnings.push_back(at(file_name, t.line) + "unexpected '" + t.text + "' skipped");
      }
      continue;
    }
    if (t.kind == Token::Kind::Name && word == "guide") {
      lex.skip_rest_of_line();
      out.warnings.push_back(at(file_name, t.line) + "material guide skipped (guides are not expanded)");
      continue;
    }
    if (t.kind == Token::Kind::Name && (word == "table" || skipped_decl_types().count(word))) {
      Token name = lex.expect_any("a declaration name");
      Token open = lex.next();
      if (!open.is("{")) lex.fail(open, "expected '{' after " + word + " " + name.text);
      if (word != "table") {
        lex.skip_braced_block();
        continue;
      }
      std::string_view body = lex.braced_block_text(open);
      Lexer table_lex(body, file_name, open.line, open.column + 1);
      try {
        tables[lowercase(name.text)] = parse_table_body(table_lex);
      } catch (const ParseError& e) {
        out.warnings.push_back(std::string(e.what()) + " (table " + name.text + " skipped)");
      }
      continue;
    }
    Token name_token = t;
    if (t.kind == Token::Kind::Name && word == "material") name_token = lex.expect_any("a material name");
    if (name_token.kind != Token::Kind::Name && name_token.kind != Token::Kind::String)
      lex.fail(name_token, "expected a material name, found '" + name_token.text + "'");
    if (!lex.peek().is("{")) {
      out.warnings.push_back(at(file_name, name_token.line) + "'" + name_token.text + "' is not followed by '{'; skipped");
      continue;
    }
    Token open = lex.next();
    std::string_view body = lex.braced_block_text(open);
    MaterialDecl m;
    m.name = name_token.text;
    m.file = file_name;
    m.line = name_token.line;
    Lexer body_lex(body, file_name, open.line, open.column + 1);
    try {
      reader.read_body(body_lex, m);
    } catch (const ParseError& e) {
      out.warnings.push_back(std::string(e.what()) + " (rest of material " + m.name + " skipped)");
    }
    out.materials.push_back(std::move(m));
  }
  return out;
}

}  // namespace cohort::scene
