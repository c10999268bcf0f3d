// A string-keyed factory: one per extension point (shape family, material, update scheme, ...).
//
// Each plug-in registers itself with one line beside its class. Asking for an unknown name throws
// UnknownName, whose message lists every valid name, so input errors can say what was allowed.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace cairn {

class UnknownName : public std::runtime_error {
 public:
  UnknownName(const std::string& what_kind, const std::string& name, std::vector<std::string> valid)
      : std::runtime_error(make_message(what_kind, name, valid)), valid_(std::move(valid)) {}
  [[nodiscard]] const std::vector<std::string>& valid() const { return valid_; }

 private:
  static std::string make_message(const std::string& kind, const std::string& name,
                                  const std::vector<std::string>& valid) {
    std::string msg = "unknown " + kind + " '" + name + "'; valid names are:";
    for (const auto& v : valid) msg += " " + v;
    return msg;
  }
  std::vector<std::string> valid_;
};

template <class Base, class... Args>
class Registry {
 public:
  using Factory = std::function<std::unique_ptr<Base>(Args...)>;
  struct Entry {
    std::string doc;
    Factory factory;
  };

  static Registry& instance() {
    static Registry registry;
    return registry;
  }

  bool add(const std::string& name, std::string doc, Factory factory) {
    entries_[name] = Entry{std::move(doc), std::move(factory)};
    return true;
  }

  [[nodiscard]] bool contains(const std::string& name) const { return entries_.count(name) != 0; }

  [[nodiscard]] std::unique_ptr<Base> create(const std::string& kind, const std::string& name,
                                             Args... args) const {
    auto it = entries_.find(name);
    if (it == entries_.end()) throw UnknownName(kind, name, names());
    return it->second.factory(std::forward<Args>(args)...);
  }

  [[nodiscard]] std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& [k, v] : entries_) out.push_back(k);
    return out;
  }

  [[nodiscard]] const std::string& doc(const std::string& name) const { return entries_.at(name).doc; }

 private:
  std::map<std::string, Entry> entries_;
};

}  // namespace cairn
