#pragma once
// The reference documentation and the shell completions, generated from the CLI's own
// option definitions (the CLI11 App every command registered itself on), so they cannot
// drift from what the program accepts. `stipplot help-export` (hidden) writes them:
// docs/reference/*.md (checked in, scripts/gen_docs.sh), the man pages and the bash, zsh
// and fish completions (made at build time and installed).
#include <CLI/CLI.hpp>
#include <map>
#include <string>
#include <vector>

namespace stipplot::cli::docgen {

// One option or positional argument as --help shows it.
struct OptionDoc {
  std::vector<std::string> shorts;  // "o" for -o
  std::vector<std::string> longs;   // "output" for --output
  std::string positional;           // the argument's name, for a positional
  std::string type;                 // TEXT, FLOAT, UINT, ...; empty for a flag
  std::string default_value;        // as --help shows it; empty for none
  std::string description;
  std::string group;
  bool required = false;
  bool many = false;                      // takes several values
  std::vector<std::string> choices;       // the values a description lists as a|b|c
  std::vector<std::string> needs, excludes;  // other options' names
  std::string envname;
};

// One command (the program itself has the path {"stipplot"}).
struct CommandDoc {
  std::vector<std::string> path;  // {"stipplot", "stipple"}
  std::string description, footer;
  std::vector<OptionDoc> positionals;
  std::vector<std::pair<std::string, std::vector<OptionDoc>>> groups;  // options by help group, in --help's order
  std::vector<CommandDoc> subcommands;                                 // the visible ones
  std::string name() const;       // "stipplot stipple"
  std::string file_stem() const;  // "stipple"; the program's own: "stipplot"
  std::string usage() const;      // "stipplot stipple [OPTIONS] input"
};

// The command tree as --help shows it: hidden commands and options (empty group) left out.
CommandDoc describe(CLI::App& app, const std::string& program = "stipplot");

// Every command in the tree, the program first, then depth first.
std::vector<const CommandDoc*> flatten(const CommandDoc& root);

// File name -> contents. Markdown: README.md (the program and its commands) and
// <command>.md per command. Man pages: stipplot.1 and stipplot-<command>.1 (roff).
std::map<std::string, std::string> markdown_pages(const CommandDoc& root);
std::map<std::string, std::string> man_pages(const CommandDoc& root, const std::string& version);
// The completion scripts: bash (file "stipplot"), zsh ("_stipplot"), fish ("stipplot.fish").
std::string bash_completion(const CommandDoc& root);
std::string zsh_completion(const CommandDoc& root);
std::string fish_completion(const CommandDoc& root);

}  // namespace stipplot::cli::docgen
