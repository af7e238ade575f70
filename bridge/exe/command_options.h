// COLMAP's option manager with options that are given as text and parsed into their types once,
// after the command line and the project file are read: closed choices (enums of NamedChoices
// tables, "auto"), lists (axes). Every command parses its options through it.
#pragma once

#include "lidar/util/named_choice.h"

#include "colmap/controllers/option_manager.h"

#include <deque>
#include <functional>
#include <string>

namespace colmap_lidar {

class CommandOptions : public colmap::OptionManager {
 public:
  // Registers --`name` as text with `default_text` as its default; Parse() passes the final text
  // to `parse`, which throws std::invalid_argument on text it does not accept.
  void AddParsedOption(const std::string& name,
                       std::string default_text,
                       std::function<void(const std::string&)> parse,
                       const std::string& help);
  // --`name` one of `table`'s names, into `*value` (whose current value is the default).
  template <typename Enum, size_t N>
  void AddChoiceOption(const std::string& name,
                       Enum* value,
                       const NamedChoices<Enum, N>& table,
                       const std::string& help = "") {
    AddParsedOption(
        name,
        ChoiceName(table, *value),
        [name, value, &table](const std::string& text) {
          *value = ChoiceFromName(table, text, "--" + name);
        },
        ChoiceNames(table) + (help.empty() ? "" : " (" + help + ")"));
  }
  // COLMAP's Parse (which exits on --help and on an unknown option), then the parsed options in
  // the order they were added.
  void Parse(int argc, char** argv);

 private:
  struct ParsedOption {
    std::string text;
    std::function<void(const std::string&)> parse;
  };
  std::deque<ParsedOption> parsed_options_;  // a deque: the manager keeps pointers to the texts
};

}  // namespace colmap_lidar
