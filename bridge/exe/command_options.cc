#include "bridge/exe/command_options.h"

namespace colmap_lidar {

void CommandOptions::AddParsedOption(const std::string& name,
                                     std::string default_text,
                                     std::function<void(const std::string&)> parse,
                                     const std::string& help) {
  parsed_options_.push_back({std::move(default_text), std::move(parse)});
  AddDefaultOption(name, &parsed_options_.back().text, help);
}

void CommandOptions::Parse(int argc, char** argv) {
  colmap::OptionManager::Parse(argc, argv);
  for (const ParsedOption& option : parsed_options_) option.parse(option.text);
}

}  // namespace colmap_lidar
