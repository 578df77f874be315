// YAML configuration loading and validation, see config.hpp.
#include "pipeline/core/config.hpp"

#include <algorithm>
#include <cstdint>
#include <fstream>

namespace sss::core {

std::string ConfigProblem::message() const {
  if (value.empty()) return "config key '" + key + "': " + reason;
  return "config key '" + key + "' = " + value + ": " + reason;
}

Rule<std::string> oneOf(std::vector<std::string> choices) {
  std::string allowed = "one of {";
  for (size_t i = 0; i < choices.size(); ++i) allowed += (i ? ", " : "") + choices[i];
  allowed += "}";
  return {[choices](const std::string& v) { return std::find(choices.begin(), choices.end(), v) != choices.end(); },
          allowed};
}

Rule<std::string> nonEmpty() {
  return {[](const std::string& v) { return !v.empty(); }, "a non-empty string"};
}

template <> std::string configTypeName<int>() { return "an integer"; }
template <> std::string configTypeName<int64_t>() { return "an integer"; }
template <> std::string configTypeName<uint32_t>() { return "a non-negative integer"; }
template <> std::string configTypeName<double>() { return "a number"; }
template <> std::string configTypeName<float>() { return "a number"; }
template <> std::string configTypeName<bool>() { return "true or false"; }
template <> std::string configTypeName<std::string>() { return "a string"; }
template <> std::string configTypeName<std::vector<double>>() { return "a list of numbers"; }
template <> std::string configTypeName<std::vector<std::string>>() { return "a list of strings"; }

std::string describeYamlValue(const YAML::Node& node) {
  if (node.IsScalar()) {
    const std::string& text = node.Scalar();
    // Quote what YAML would read as a string, so "12" (string) and 12 stand apart in the message.
    if (node.Tag() == "!") return "\"" + text + "\"";
    return text;
  }
  YAML::Emitter out;
  out << YAML::Flow << node;
  return out.c_str();
}

ConfigSection::ConfigSection(YAML::Node node, std::string path, std::shared_ptr<std::vector<ConfigProblem>> problems)
    : node_(std::move(node)), path_(std::move(path)), problems_(std::move(problems)) {}

bool ConfigSection::has(const std::string& key) const {
  const YAML::Node child = lookup(key);
  return child.IsDefined() && !child.IsNull();
}

ConfigSection ConfigSection::section(const std::string& key) {
  read_keys_.insert(key);
  const YAML::Node child = lookup(key);
  if (!child.IsDefined() || child.IsNull()) {
    // A fresh empty map: assigning to the invalid node yaml-cpp returns for a missing key throws.
    return ConfigSection(YAML::Node(YAML::NodeType::Map), keyPath(key), problems_);
  }
  if (!child.IsMap()) {
    addProblem(key, describeYamlValue(child), "wrong type; expected a section (a map of keys)");
    return ConfigSection(YAML::Node(YAML::NodeType::Map), keyPath(key), problems_);
  }
  return ConfigSection(child, keyPath(key), problems_);
}

std::vector<ConfigSection> ConfigSection::sequence(const std::string& key) {
  read_keys_.insert(key);
  std::vector<ConfigSection> items;
  const YAML::Node child = lookup(key);
  if (!child.IsDefined() || child.IsNull()) return items;
  if (!child.IsSequence()) {
    addProblem(key, describeYamlValue(child), "wrong type; expected a list of sections");
    return items;
  }
  for (size_t i = 0; i < child.size(); ++i) {
    const std::string item_path = keyPath(key) + "[" + std::to_string(i) + "]";
    if (!child[i].IsMap()) {
      addProblem(key + "[" + std::to_string(i) + "]", describeYamlValue(child[i]), "wrong type; expected a section (a map of keys)");
      continue;
    }
    items.emplace_back(child[i], item_path, problems_);
  }
  return items;
}

void ConfigSection::addProblem(const std::string& key, const std::string& value, const std::string& reason) {
  problems_->push_back({keyPath(key), value, reason});
}

void ConfigSection::rejectUnknownKeys() {
  if (!node_.IsMap()) return;
  std::string known;
  for (const std::string& k : read_keys_) known += (known.empty() ? "" : ", ") + k;
  for (const auto& entry : node_) {
    const std::string key = entry.first.as<std::string>();
    if (read_keys_.count(key) == 0) addProblem(key, "", "unknown key; known keys here: {" + known + "}");
  }
}

Config Config::fromString(const std::string& yaml_text, const std::string& source_name) {
  Config config;
  try {
    config.node_ = YAML::Load(yaml_text);
    if (config.node_.IsNull()) config.node_ = YAML::Node(YAML::NodeType::Map);
    if (!config.node_.IsMap()) {
      config.problems_->push_back({"<root>", "", source_name + " must hold a map of sections"});
      config.node_ = YAML::Node(YAML::NodeType::Map);
    }
  } catch (const YAML::ParserException& e) {
    config.problems_->push_back({"<root>", "", source_name + ": YAML syntax error at line " +
                                                  std::to_string(e.mark.line + 1) + ", column " +
                                                  std::to_string(e.mark.column + 1) + ": " + e.msg});
    config.node_ = YAML::Node(YAML::NodeType::Map);
  }
  return config;
}

Config Config::fromFile(const std::string& path) {
  std::ifstream file(path);
  if (!file) {
    Config config;
    config.node_ = YAML::Node(YAML::NodeType::Map);
    config.problems_->push_back({"<root>", "", "cannot open config file '" + path + "'"});
    return config;
  }
  std::stringstream text;
  text << file.rdbuf();
  return fromString(text.str(), path);
}

std::string Config::problemReport() const {
  std::string report;
  for (const ConfigProblem& problem : *problems_) report += problem.message() + "\n";
  return report;
}

}  // namespace sss::core
