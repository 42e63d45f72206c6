// A string-keyed map that lists its keys the way a JavaScript object does:
// array-index keys ("0", "12") first in numeric order, then the others in
// insertion order.  The reference compiler keeps its legend tables in plain
// objects and some of its loops depend on that order.
#pragma once

#include <algorithm>
#include <string>
#include <unordered_map>
#include <vector>

#include "base/JsString.h"

namespace psc {

template <typename V>
class JsObject {
public:
    bool has(const std::string& key) const { return values_.count(key) > 0; }
    V& at(const std::string& key) { return values_.at(key); }
    const V& at(const std::string& key) const { return values_.at(key); }
    const V* find(const std::string& key) const {
        auto it = values_.find(key);
        return it == values_.end() ? nullptr : &it->second;
    }
    V* find(const std::string& key) {
        auto it = values_.find(key);
        return it == values_.end() ? nullptr : &it->second;
    }
    void set(const std::string& key, V value) {
        if (!has(key)) insertion_.push_back(key);
        values_[key] = std::move(value);
    }
    void erase(const std::string& key) {
        if (values_.erase(key)) insertion_.erase(std::find(insertion_.begin(), insertion_.end(), key));
    }
    size_t size() const { return values_.size(); }
    bool empty() const { return values_.empty(); }
    // Object.keys(): a snapshot, safe to iterate while the object changes.
    std::vector<std::string> keys() const { return js::objectKeyOrder(insertion_); }

private:
    std::vector<std::string> insertion_;
    std::unordered_map<std::string, V> values_;
};

}  // namespace psc
