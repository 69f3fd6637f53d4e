#include "cli/docgen.hpp"

#include <regex>
#include <set>
#include <sstream>

namespace stipplot::cli::docgen {

namespace {

std::string join_names(const std::vector<std::string>& v, const std::string& sep) {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : sep) + s;
  return out;
}

std::vector<std::string> split_lines(const std::string& s) {
  std::vector<std::string> lines;
  std::istringstream in(s);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  while (!lines.empty() && lines.back().empty()) lines.pop_back();
  return lines;
}

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size())) s.replace(at, from.size(), to);
  return s;
}

// The values a description lists as "a|b|c", at its start or after ": " ("tone|linear
// (tone: ...)", "... wider than the pen: spiral|hatch|none"); none when it lists none.
std::vector<std::string> listed_choices(const std::string& description) {
  static const std::regex list(R"((^|: )([a-z0-9][a-z0-9-]*( ?\| ?[a-z0-9][a-z0-9-]*)+)( |,|$))");
  std::smatch m;
  if (!std::regex_search(description, m, list)) return {};
  std::vector<std::string> out;
  std::string item;
  for (char c : m[2].str()) {
    if (c == '|') {
      out.push_back(item);
      item.clear();
    } else if (c != ' ') {
      item += c;
    }
  }
  out.push_back(item);
  return out;
}

OptionDoc describe_option(CLI::Option& o) {
  OptionDoc d;
  d.shorts = o.get_snames();
  d.longs = o.get_lnames();
  if (!o.nonpositional()) d.positional = o.get_name();
  if (o.get_type_size() > 0) d.type = o.get_type_name();
  d.default_value = o.get_default_str();
  d.description = o.get_description();
  d.group = o.get_group();
  d.required = o.get_required();
  d.many = o.get_items_expected_max() > 1;
  d.choices = listed_choices(d.description);
  for (CLI::Option* n : o.get_needs()) d.needs.push_back(n->get_name());
  for (CLI::Option* x : o.get_excludes()) d.excludes.push_back(x->get_name());
  d.envname = o.get_envname();
  return d;
}

CommandDoc describe_app(CLI::App& app, std::vector<std::string> path) {
  CommandDoc c;
  c.path = std::move(path);
  c.description = app.get_description();
  c.footer = app.get_footer();
  for (CLI::Option* o : app.get_options([](CLI::Option*) { return true; })) {
    if (o->get_group().empty()) continue;  // hidden
    OptionDoc d = describe_option(*o);
    if (!d.positional.empty()) {
      c.positionals.push_back(std::move(d));
      continue;
    }
    auto g = std::find_if(c.groups.begin(), c.groups.end(), [&](const auto& e) { return e.first == d.group; });
    if (g == c.groups.end()) {
      c.groups.emplace_back(d.group, std::vector<OptionDoc>{});
      g = c.groups.end() - 1;
    }
    g->second.push_back(std::move(d));
  }
  for (CLI::App* sub : app.get_subcommands([](CLI::App* s) { return !s->get_name().empty() && !s->get_group().empty(); })) {
    std::vector<std::string> p = c.path;
    p.push_back(sub->get_name());
    c.subcommands.push_back(describe_app(*sub, p));
  }
  return c;
}

void flatten_into(const CommandDoc& c, std::vector<const CommandDoc*>& out) {
  out.push_back(&c);
  for (const auto& s : c.subcommands) flatten_into(s, out);
}

std::vector<std::string> dashed(const OptionDoc& o) {
  std::vector<std::string> v;
  for (const auto& s : o.shorts) v.push_back("-" + s);
  for (const auto& l : o.longs) v.push_back("--" + l);
  return v;
}

std::vector<const OptionDoc*> all_options(const CommandDoc& c) {
  std::vector<const OptionDoc*> v;
  for (const auto& [group, opts] : c.groups)
    for (const auto& o : opts) v.push_back(&o);
  return v;
}

// "Needs --x. Excludes --y. Environment: $Z." for the options that have such.
std::string relations(const OptionDoc& o) {
  std::string s;
  if (!o.needs.empty()) s += " Needs " + join_names(o.needs, ", ") + ".";
  if (!o.excludes.empty()) s += " Excludes " + join_names(o.excludes, ", ") + ".";
  if (!o.envname.empty()) s += " Environment: $" + o.envname + ".";
  return s;
}

// A description as a sentence: ending in a full stop.
std::string sentence(const std::string& s) {
  if (s.empty() || s.back() == '.' || s.back() == '!' || s.back() == '?') return s;
  return s + ".";
}

// CLI11 puts ungrouped options in "Options": under the heading "Options" that says "General".
std::string group_title(const std::string& group) { return group == "Options" ? "General" : group; }

std::string value_text(const OptionDoc& o) {
  if (o.type.empty()) return "";
  return o.type + (o.many ? " ..." : "");
}

// The first words of a description, for a completion menu.
std::string short_description(const std::string& s, size_t limit = 80) {
  std::string one = replace_all(s, "\n", " ");
  if (one.size() <= limit) return one;
  size_t cut = one.rfind(' ', limit - 3);
  if (cut == std::string::npos || cut < limit / 2) cut = limit - 3;
  return one.substr(0, cut) + "...";
}

// ---- Markdown ----

std::string md_cell(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '|': out += "\\|"; break;
      case '*': out += "\\*"; break;
      case '\\': out += "\\\\"; break;
      case '<': out += "&lt;"; break;
      case '\n': out += "<br>"; break;
      default: out += c;
    }
  }
  return out;
}

std::string md_code(const std::string& s) { return "`" + replace_all(s, "|", "\\|") + "`"; }

const char* kGenerated =
    "<!-- Generated by scripts/gen_docs.sh (stipplot help-export --format md) from the program's own option "
    "definitions: do not edit; change the option's help text and regenerate. -->\n";

void md_option_table(std::ostringstream& md, const std::vector<OptionDoc>& opts) {
  md << "| Option | Value | Default | Description |\n|---|---|---|---|\n";
  for (const auto& o : opts) {
    std::vector<std::string> names;
    for (const auto& n : dashed(o)) names.push_back(md_code(n));
    std::string value = value_text(o).empty() ? "" : md_code(value_text(o));
    if (o.required) value += value.empty() ? "required" : ", required";
    md << "| " << join_names(names, ", ") << " | " << value << " | "
       << (o.default_value.empty() ? "" : md_code(o.default_value)) << " | " << md_cell(o.description + relations(o))
       << " |\n";
  }
}

void md_options(std::ostringstream& md, const CommandDoc& c) {
  if (!c.positionals.empty()) {
    md << "\n## Arguments\n\n| Argument | Value | Description |\n|---|---|---|\n";
    for (const auto& p : c.positionals)
      md << "| " << md_code(p.positional) << " | " << md_code(value_text(p)) << (p.required ? ", required" : "")
         << " | " << md_cell(p.description + relations(p)) << " |\n";
  }
  if (c.groups.empty()) return;
  md << "\n## Options\n";
  for (const auto& [group, opts] : c.groups) {
    if (c.groups.size() > 1) md << "\n### " << group_title(group) << "\n";
    md << "\n";
    md_option_table(md, opts);
  }
}

std::string md_command(const CommandDoc& c) {
  std::ostringstream md;
  md << "# " << c.name() << "\n\n" << kGenerated << "\n" << c.description << "\n\n```text\n" << c.usage() << "\n```\n";
  if (!c.footer.empty()) md << "\n```text\n" << join_names(split_lines(c.footer), "\n") << "\n```\n";
  if (!c.subcommands.empty()) {
    md << "\n## Commands\n\n| Command | What it does |\n|---|---|\n";
    for (const auto& s : c.subcommands)
      md << "| [" << md_code(s.path.back()) << "](" << s.file_stem() << ".md) | " << md_cell(s.description) << " |\n";
  }
  md_options(md, c);
  if (c.path.size() > 1) md << "\nSee also: [all commands](README.md), `man " << "stipplot-" << c.file_stem() << "`.\n";
  return md.str();
}

// ---- roff (man(7)) ----

// Text for roff: backslashes and hyphens escaped, no line starting with a control character.
std::string roff_text(const std::string& s) {
  std::string out;
  bool line_start = true;
  for (char c : s) {
    if (line_start && (c == '.' || c == '\'')) out += "\\&";
    line_start = c == '\n';
    if (c == '\\') out += "\\e";
    else if (c == '-') out += "\\-";
    else out += c;
  }
  return out;
}

std::string roff_bold(const std::string& s) { return "\\fB" + roff_text(s) + "\\fR"; }
std::string roff_italic(const std::string& s) { return "\\fI" + roff_text(s) + "\\fR"; }

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::string man_name(const CommandDoc& c) { return join_names(c.path, "-"); }

void man_option(std::ostringstream& man, const OptionDoc& o) {
  std::vector<std::string> names;
  for (const auto& n : dashed(o)) names.push_back(roff_bold(n));
  man << ".TP\n" << join_names(names, ", ");
  if (!o.type.empty()) man << " " << roff_italic(value_text(o));
  std::vector<std::string> notes;
  if (o.required) notes.push_back("required");
  if (!o.default_value.empty()) notes.push_back("default: " + o.default_value);
  if (!notes.empty()) man << " (" << roff_text(join_names(notes, ", ")) << ")";
  man << "\n" << roff_text(o.description + relations(o)) << "\n";
}

void man_verbatim(std::ostringstream& man, const std::string& text) {
  man << ".PP\n.nf\n";
  for (const auto& line : split_lines(text)) man << (line.empty() ? ".sp" : roff_text(line)) << "\n";
  man << ".fi\n";
}

std::string man_page(const CommandDoc& c, const CommandDoc& root, const std::string& version) {
  std::ostringstream man;
  std::string description = c.description;
  if (c.path.size() == 1 && description.rfind(c.path[0] + ": ", 0) == 0) description.erase(0, c.path[0].size() + 2);
  man << ".\\\" Generated by stipplot help-export from the program's own option definitions; do not edit.\n"
      << ".TH " << upper(man_name(c)) << " 1 \"\" \"stipplot " << version << "\" \"stipplot manual\"\n"
      << ".nh\n.ad l\n"  // no hyphenation, ragged right: option names and values stay whole
      << ".SH NAME\n" << roff_text(man_name(c)) << " \\- " << roff_text(description) << "\n"
      << ".SH SYNOPSIS\n" << roff_bold(c.name()) << " [" << roff_italic("OPTIONS") << "]";
  for (const auto& p : c.positionals) {
    std::string arg = roff_italic(p.positional) + (p.many ? " ..." : "");
    man << " " << (p.required ? arg : "[" + arg + "]");
  }
  if (!c.subcommands.empty()) man << " " << roff_italic("COMMAND") << " [" << roff_italic("ARGS") << "]";
  man << "\n.SH DESCRIPTION\n" << roff_text(description) << "\n";
  if (!c.footer.empty()) man_verbatim(man, c.footer);
  if (!c.subcommands.empty()) {
    man << ".SH COMMANDS\n";
    for (const auto& s : c.subcommands)
      man << ".TP\n" << roff_bold(s.path.back()) << "\n" << roff_text(sentence(s.description)) << " See "
          << roff_bold(man_name(s)) << "(1).\n";
  }
  if (!c.positionals.empty()) {
    man << ".SH ARGUMENTS\n";
    for (const auto& p : c.positionals)
      man << ".TP\n" << roff_italic(p.positional) << " (" << roff_text(value_text(p)) << (p.required ? ", required" : "")
          << ")\n" << roff_text(p.description + relations(p)) << "\n";
  }
  if (!c.groups.empty()) {
    man << ".SH OPTIONS\n";
    for (const auto& [group, opts] : c.groups) {
      if (c.groups.size() > 1) man << ".SS " << roff_text(group_title(group)) << "\n";
      for (const auto& o : opts) man_option(man, o);
    }
  }
  if (c.path.size() == 1) {
    // Where the program finds what --pens NAME and --profile NAME name.
    man << ".SH ENVIRONMENT\n.TP\n" << roff_bold("STIPPLOT_PENS")
        << "\nA folder searched first for a palette given by name: --pens NAME reads NAME.toml.\n.TP\n"
        << roff_bold("STIPPLOT_PROFILES") << "\nA folder searched first for a device profile given by name.\n"
        << ".SH FILES\n.TP\n" << roff_italic("../share/stipplot/pens/*.toml")
        << "\n" << roff_text("Beside the executable (/usr/share/stipplot/pens for /usr/bin/stipplot): the shipped "
                              "pen palettes, by name (--pens fineliner12). A path (with a / or ending in .toml) is read as it is.")
        << "\n.TP\n" << roff_italic("../share/stipplot/profiles/*.toml") << "\n"
        << roff_text("The shipped device profiles, by name (--profile hp7475a-a4); stipplot profiles lists them.") << "\n";
  }
  man << ".SH SEE ALSO\n";
  std::vector<std::string> see;
  for (const CommandDoc* other : flatten(root))
    if (other != &c) see.push_back(roff_bold(man_name(*other)) + "(1)");
  man << join_names(see, ",\n") << "\n";
  return man.str();
}

// ---- shell completions ----

// Inside single quotes in sh: ' becomes '\''.
std::string sh_quote(const std::string& s) { return "'" + replace_all(s, "'", "'\\''") + "'"; }

bool takes_value(const OptionDoc& o) { return !o.type.empty(); }
bool is_named(const OptionDoc& o, const std::string& name) {
  return std::find(o.longs.begin(), o.longs.end(), name) != o.longs.end();
}

// The words of a command's case arm: its options, then those taking a value.
std::string bash_case(const CommandDoc& c, const std::string& label) {
  std::vector<std::string> opts, values;
  std::ostringstream arm;
  std::ostringstream special;
  for (const OptionDoc* o : all_options(c)) {
    for (const auto& n : dashed(*o)) opts.push_back(n);
    if (!takes_value(*o)) continue;
    for (const auto& n : dashed(*o)) values.push_back(n);
    std::string words;
    if (is_named(*o, "profile")) words = "$(_stipplot_profiles)";
    else if (is_named(*o, "pens")) words = "$(_stipplot_pens)";
    else if (!o->choices.empty()) words = join_names(o->choices, " ");
    else continue;
    const bool files = is_named(*o, "profile") || is_named(*o, "pens");
    special << "        " << join_names(dashed(*o), "|") << ") COMPREPLY=($(compgen -W \"" << words << "\" -- \"$cur\")"
            << (files ? " $(compgen -f -- \"$cur\")" : "") << "); return ;;\n";
  }
  std::vector<std::string> subs;
  for (const auto& s : c.subcommands) subs.push_back(s.path.back());
  arm << "    " << label << ")\n"
      << "      opts=" << sh_quote(join_names(opts, " ")) << "\n"
      << "      values=" << sh_quote(join_names(values, " ")) << "\n"
      << "      subs=" << sh_quote(join_names(subs, " ")) << "\n"
      << "      files=" << (c.positionals.empty() ? 0 : 1) << "\n";
  if (!special.str().empty()) arm << "      case $prev in\n" << special.str() << "      esac\n";
  arm << "      ;;\n";
  return arm.str();
}

// zsh _arguments: '[...]' may not hold an unescaped bracket; the whole spec is single-quoted.
std::string zsh_description(const std::string& s) {
  std::string d = short_description(s);
  d = replace_all(d, "\\", "\\\\");
  d = replace_all(d, "[", "\\[");
  d = replace_all(d, "]", "\\]");
  return d;
}

std::string zsh_spec(const OptionDoc& o) {
  const auto names = dashed(o);
  std::string action;
  if (takes_value(o)) {
    std::string message = o.type.substr(0, o.type.find(':'));
    for (char& ch : message) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    if (is_named(o, "profile")) action = "_stipplot_profiles";
    else if (is_named(o, "pens")) action = "_stipplot_pens";
    else if (!o.choices.empty()) action = "(" + join_names(o.choices, " ") + ")";
    else action = "_files";
    action = ":" + message + ":" + action;
  }
  const std::string body = "[" + zsh_description(o.description) + "]" + action;
  if (names.size() == 1) return sh_quote(names[0] + body);
  std::string spec = sh_quote("(" + join_names(names, " ") + ")") + "{" + join_names(names, ",") + "}" + sh_quote(body);
  return spec;
}

std::string fish_quote(const std::string& s) {
  return "'" + replace_all(replace_all(s, "\\", "\\\\"), "'", "\\'") + "'";
}

}  // namespace

std::string CommandDoc::name() const { return join_names(path, " "); }

std::string CommandDoc::file_stem() const {
  if (path.size() == 1) return path[0];
  return join_names(std::vector<std::string>(path.begin() + 1, path.end()), "-");
}

std::string CommandDoc::usage() const {
  std::string u = name() + " [OPTIONS]";
  for (const auto& p : positionals) {
    const std::string arg = p.positional + (p.many ? " ..." : "");
    u += " " + (p.required ? arg : "[" + arg + "]");
  }
  if (!subcommands.empty()) u += " COMMAND [ARGS]";
  return u;
}

CommandDoc describe(CLI::App& app, const std::string& program) { return describe_app(app, {program}); }

std::vector<const CommandDoc*> flatten(const CommandDoc& root) {
  std::vector<const CommandDoc*> out;
  flatten_into(root, out);
  return out;
}

std::map<std::string, std::string> markdown_pages(const CommandDoc& root) {
  std::map<std::string, std::string> pages;
  for (const CommandDoc* c : flatten(root)) {
    if (c == &root) {
      std::ostringstream md;
      md << "# " << root.name() << " command reference\n\n" << kGenerated << "\n" << root.description << "\n\n```text\n"
         << root.usage() << "\n```\n\n"
         << "Every command prints its page with `" << root.name() << " COMMAND --help`, and `man " << root.name()
         << "-COMMAND` shows it once installed.\n";
      if (!root.footer.empty()) md << "\n```text\n" << join_names(split_lines(root.footer), "\n") << "\n```\n";
      md << "\n## Commands\n\n| Command | What it does |\n|---|---|\n";
      for (const CommandDoc* s : flatten(root))
        if (s != &root)
          md << "| [" << md_code(s->name().substr(root.name().size() + 1)) << "](" << s->file_stem() << ".md) | "
             << md_cell(s->description) << " |\n";
      md_options(md, root);
      pages["README.md"] = md.str();
    } else {
      pages[c->file_stem() + ".md"] = md_command(*c);
    }
  }
  return pages;
}

std::map<std::string, std::string> man_pages(const CommandDoc& root, const std::string& version) {
  std::map<std::string, std::string> pages;
  for (const CommandDoc* c : flatten(root)) pages[man_name(*c) + ".1"] = man_page(*c, root, version);
  return pages;
}

std::string bash_completion(const CommandDoc& root) {
  const std::string p = root.name();
  std::ostringstream sh;
  sh << "# bash completion for " << p << ": generated by `" << p
     << " help-export --format bash` from its option definitions; do not edit.\n"
     << "_" << p << "_profiles() { \"${COMP_WORDS[0]}\" profiles 2>/dev/null | cut -d' ' -f1; }\n"
     << "# The shipped palettes, found as the program finds them: ../share/" << p << "/pens beside it.\n"
     << "_" << p << "_pens() {\n"
     << "  local bin f\n"
     << "  bin=$(command -v \"${COMP_WORDS[0]}\" 2>/dev/null) || return 0\n"
     << "  bin=$(readlink -f \"$bin\")\n"
     << "  for f in \"${bin%/*}\"/../share/" << p << "/pens/*.toml; do [ -e \"$f\" ] && basename \"$f\" .toml; done\n"
     << "}\n"
     << "_" << p << "() {\n"
     << "  local cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD-1]} i w\n"
     << "  local opts values subs files\n"
     << "  # The command path so far: every word not an option nor an option's value.\n"
     << "  local path=" << p << " skip=0\n"
     << "  for ((i = 1; i < COMP_CWORD; i++)); do\n"
     << "    w=${COMP_WORDS[i]}\n"
     << "    if ((skip)); then skip=0; continue; fi\n"
     << "    case \" $(_" << p << "_values \"$path\") \" in *\" $w \"*) skip=1; continue ;; esac\n"
     << "    case $w in -*) continue ;; esac\n"
     << "    case \" $(_" << p << "_subs \"$path\") \" in *\" $w \"*) path=\"$path $w\" ;; esac\n"
     << "  done\n"
     << "  case $path in\n";
  std::ostringstream values, subs;
  for (const CommandDoc* c : flatten(root)) {
    sh << bash_case(*c, sh_quote(c->name()));
    std::vector<std::string> v, s;
    for (const OptionDoc* o : all_options(*c))
      if (takes_value(*o))
        for (const auto& n : dashed(*o)) v.push_back(n);
    for (const auto& sub : c->subcommands) s.push_back(sub.path.back());
    values << "    " << sh_quote(c->name()) << ") echo " << sh_quote(join_names(v, " ")) << " ;;\n";
    subs << "    " << sh_quote(c->name()) << ") echo " << sh_quote(join_names(s, " ")) << " ;;\n";
  }
  sh << "  esac\n"
     << "  if [[ \" $values \" == *\" $prev \"* ]]; then COMPREPLY=($(compgen -f -- \"$cur\")); return; fi\n"
     << "  if [[ $cur == -* ]]; then COMPREPLY=($(compgen -W \"$opts\" -- \"$cur\")); return; fi\n"
     << "  COMPREPLY=($(compgen -W \"$subs\" -- \"$cur\"))\n"
     << "  ((files)) && COMPREPLY+=($(compgen -f -- \"$cur\"))\n"
     << "  return 0\n"
     << "}\n"
     << "_" << p << "_values() {\n  case $1 in\n" << values.str() << "  esac\n}\n"
     << "_" << p << "_subs() {\n  case $1 in\n" << subs.str() << "  esac\n}\n"
     << "complete -o filenames -F _" << p << " " << p << "\n";
  return sh.str();
}

std::string zsh_completion(const CommandDoc& root) {
  const std::string p = root.name();
  std::ostringstream z;
  z << "#compdef " << p << "\n"
    << "# zsh completion for " << p << ": generated by `" << p
    << " help-export --format zsh` from its option definitions; do not edit.\n"
    << "_" << p << "_profiles() {\n"
    << "  local -a profiles\n"
    << "  profiles=(${${(f)\"$(_call_program profiles " << p << " profiles 2>/dev/null)\"}%% *})\n"
    << "  _alternative 'profiles:profile:compadd -a profiles' 'files:file:_files'\n"
    << "}\n"
    << "_" << p << "_pens() {\n"
    << "  local -a pens\n"
    << "  local bin=${commands[" << p << "]:A}\n"
    << "  [[ -n $bin ]] && pens=(${bin:h}/../share/" << p << "/pens/*.toml(N:t:r))\n"
    << "  _alternative 'pens:palette:compadd -a pens' 'files:file:_files'\n"
    << "}\n";
  // One function per command: its options and positionals, then its subcommands.
  for (const CommandDoc* c : flatten(root)) {
    const std::string fn = "_" + join_names(c->path, "_");
    std::string safe_fn;
    for (char ch : fn) safe_fn += ch == '-' ? '_' : ch;
    z << safe_fn << "() {\n  local curcontext=$curcontext state line\n  typeset -A opt_args\n  _arguments -C";
    for (const OptionDoc* o : all_options(*c)) z << " \\\n    " << zsh_spec(*o);
    int n = 0;
    for (const auto& pos : c->positionals)
      z << " \\\n    " << sh_quote((pos.many ? "*" : std::to_string(++n)) + ":" + pos.positional + ":_files");
    if (!c->subcommands.empty()) z << " \\\n    '1: :->command' \\\n    '*:: :->args'";
    z << "\n";
    if (!c->subcommands.empty()) {
      z << "  case $state in\n    command)\n      local -a subcommands=(\n";
      for (const auto& s : c->subcommands)
        z << "        " << sh_quote(s.path.back() + ":" + replace_all(short_description(s.description), ":", "\\:")) << "\n";
      z << "      )\n      _describe -t commands command subcommands ;;\n    args)\n      case $words[1] in\n";
      for (const auto& s : c->subcommands) {
        std::string sub_fn;
        for (char ch : "_" + join_names(s.path, "_")) sub_fn += ch == '-' ? '_' : ch;
        z << "        " << s.path.back() << ") " << sub_fn << " ;;\n";
      }
      z << "      esac ;;\n  esac\n";
    }
    z << "}\n";
  }
  z << "_" << p << " \"$@\"\n";
  return z.str();
}

std::string fish_completion(const CommandDoc& root) {
  const std::string p = root.name();
  std::ostringstream f;
  f << "# fish completion for " << p << ": generated by `" << p
    << " help-export --format fish` from its option definitions; do not edit.\n"
    << "complete -c " << p << " -f\n"
    << "function __" << p << "_pens\n"
    << "    set -l bin (command -s " << p << "; or return)\n"
    << "    for f in (path dirname (path resolve $bin))/../share/" << p << "/pens/*.toml\n"
    << "        path change-extension '' (path basename $f)\n"
    << "    end\n"
    << "end\n";
  for (const CommandDoc* c : flatten(root)) {
    // Where this command's words complete: its own path seen, none of its subcommands.
    std::string cond;
    if (c->path.size() == 1) {
      cond = "__fish_use_subcommand";
    } else {
      cond = "__fish_seen_subcommand_from " + c->path.back();
      if (c->path.size() > 2) cond = "__fish_seen_subcommand_from " + c->path[c->path.size() - 2] + "; and " + cond;
    }
    if (!c->subcommands.empty() && c->path.size() > 1) {
      std::vector<std::string> subs;
      for (const auto& s : c->subcommands) subs.push_back(s.path.back());
      cond += "; and not __fish_seen_subcommand_from " + join_names(subs, " ");
    }
    const std::string head = "complete -c " + p + " -n " + fish_quote(cond);
    for (const auto& s : c->subcommands)
      f << head << " -a " << s.path.back() << " -d " << fish_quote(short_description(s.description)) << "\n";
    for (const OptionDoc* o : all_options(*c)) {
      f << head;
      for (const auto& s : o->shorts) f << " -s " << s;
      for (const auto& l : o->longs) f << " -l " << l;
      if (is_named(*o, "profile"))
        f << " -r -F -a " << fish_quote("(" + p + " profiles 2>/dev/null | string replace -r ' .*' '')");
      else if (is_named(*o, "pens"))
        f << " -r -F -a " << fish_quote("(__" + p + "_pens)");
      else if (!o->choices.empty())
        f << " -x -a " << fish_quote(join_names(o->choices, " "));
      else if (takes_value(*o))
        f << " -r -F";
      f << " -d " << fish_quote(short_description(o->description)) << "\n";
    }
    if (!c->positionals.empty()) f << head << " -F\n";
  }
  return f.str();
}

}  // namespace stipplot::cli::docgen
