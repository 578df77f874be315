// YAML configuration: one file per deployment, one section per process/module. A ConfigSection
// fills a module's Options struct and collects every problem (missing key, wrong type, value not
// allowed, unknown key) as a message that names the key, the bad value and what is allowed.
// Only these loaders read YAML; the maths only sees Options structs.
#pragma once

#include <yaml-cpp/yaml.h>

#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace sss::core {

struct ConfigProblem {
  std::string key;     // full dotted path, e.g. "matcher.patch_size"
  std::string value;   // the offending value as written, empty when missing
  std::string reason;  // what is wrong and what is allowed
  std::string message() const;
};

// A constraint on a value with a human-readable description of what is allowed.
template <typename T>
struct Rule {
  std::function<bool(const T&)> accepts;
  std::string allowed;  // e.g. "a value in [3, 31]"
};

template <typename T>
Rule<T> inRange(T min, T max) {
  std::ostringstream text;
  text << "a value in [" << min << ", " << max << "]";
  return {[min, max](const T& v) { return v >= min && v <= max; }, text.str()};
}
template <typename T>
Rule<T> atLeast(T min) {
  std::ostringstream text;
  text << "a value >= " << min;
  return {[min](const T& v) { return v >= min; }, text.str()};
}
template <typename T>
Rule<T> greaterThan(T min) {
  std::ostringstream text;
  text << "a value > " << min;
  return {[min](const T& v) { return v > min; }, text.str()};
}
Rule<std::string> oneOf(std::vector<std::string> choices);
Rule<std::string> nonEmpty();
template <typename T>
Rule<T> satisfies(std::function<bool(const T&)> predicate, std::string allowed) {
  return {std::move(predicate), std::move(allowed)};
}

template <typename T>
std::string configTypeName();

class ConfigSection {
 public:
  // A section over node at the dotted path (empty for the root).
  ConfigSection(YAML::Node node, std::string path, std::shared_ptr<std::vector<ConfigProblem>> problems);

  // Reads key into value; a missing key is a problem. Value is left unchanged on any problem.
  template <typename T>
  void required(const std::string& key, T& value, const std::vector<Rule<T>>& rules = {}) {
    read(key, value, rules, true);
  }
  // Reads key into value when present; otherwise value keeps its default.
  template <typename T>
  void optional(const std::string& key, T& value, const std::vector<Rule<T>>& rules = {}) {
    read(key, value, rules, false);
  }

  bool has(const std::string& key) const;
  // A sub-section; a missing one is empty (every optional key keeps its default).
  ConfigSection section(const std::string& key);
  // A list of sections (a YAML sequence of maps), each named key[i] in problems; a missing key is
  // an empty list.
  std::vector<ConfigSection> sequence(const std::string& key);
  // Adds a problem for a rule that spans several keys (e.g. "min < max").
  void addProblem(const std::string& key, const std::string& value, const std::string& reason);
  // Adds a problem for every key of this section that no one read: catches typos.
  void rejectUnknownKeys();

  std::string keyPath(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  const std::vector<ConfigProblem>& problems() const { return *problems_; }
  bool ok() const { return problems_->empty(); }

 private:
  template <typename T>
  void read(const std::string& key, T& value, const std::vector<Rule<T>>& rules, bool is_required);

  // Const lookup: a non-const operator[] would insert the key into the map.
  YAML::Node lookup(const std::string& key) const {
    const YAML::Node& node = node_;
    return node.IsMap() ? node[key] : YAML::Node();
  }

  YAML::Node node_;
  std::string path_;
  std::set<std::string> read_keys_;
  std::shared_ptr<std::vector<ConfigProblem>> problems_;
};

// A parsed configuration file (or string) and the root section over it.
class Config {
 public:
  // Parse errors come back as a problem with the file name and line, never as an exception.
  static Config fromFile(const std::string& path);
  static Config fromString(const std::string& yaml_text, const std::string& source_name = "<string>");

  ConfigSection root() { return ConfigSection(node_, "", problems_); }
  ConfigSection section(const std::string& key) { return root().section(key); }
  const std::vector<ConfigProblem>& problems() const { return *problems_; }
  bool ok() const { return problems_->empty(); }
  // All problems, one per line, for a log message or stderr.
  std::string problemReport() const;

 private:
  Config() : problems_(std::make_shared<std::vector<ConfigProblem>>()) {}
  YAML::Node node_;
  std::shared_ptr<std::vector<ConfigProblem>> problems_;
};

// ---- implementation of the template read ------------------------------------------------------

std::string describeYamlValue(const YAML::Node& node);

template <typename T>
void ConfigSection::read(const std::string& key, T& value, const std::vector<Rule<T>>& rules, bool is_required) {
  read_keys_.insert(key);
  const YAML::Node child = lookup(key);
  if (!child.IsDefined() || child.IsNull()) {
    if (is_required) addProblem(key, "", "missing; required: " + configTypeName<T>());
    return;
  }
  T parsed{};
  try {
    parsed = child.as<T>();
  } catch (const YAML::Exception&) {
    addProblem(key, describeYamlValue(child), "wrong type; expected " + configTypeName<T>());
    return;
  }
  for (const Rule<T>& rule : rules) {
    if (!rule.accepts(parsed)) {
      addProblem(key, describeYamlValue(child), "not allowed; expected " + rule.allowed);
      return;
    }
  }
  value = parsed;
}

}  // namespace sss::core
