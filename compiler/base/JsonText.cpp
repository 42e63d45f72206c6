#include "base/JsonText.h"

#include <algorithm>

#include "base/JsString.h"

namespace psc::json {

namespace {
constexpr size_t kWidth = 110;
}

Value Value::boolean(bool b) {
    Value v;
    v.kind_ = Kind::Bool;
    v.bool_ = b;
    return v;
}
Value Value::integer(int64_t i) {
    Value v;
    v.kind_ = Kind::Int;
    v.int_ = i;
    return v;
}
Value Value::string(std::string s) {
    Value v;
    v.kind_ = Kind::String;
    v.string_ = std::move(s);
    return v;
}
Value Value::array() {
    Value v;
    v.kind_ = Kind::Array;
    return v;
}
Value Value::object() {
    Value v;
    v.kind_ = Kind::Object;
    return v;
}

Value& Value::push(Value v) {
    items_.push_back(std::move(v));
    return *this;
}
Value& Value::set(const std::string& key, Value v) {
    for (auto& f : fields_) {
        if (f.first == key) {
            f.second = std::move(v);
            return *this;
        }
    }
    fields_.emplace_back(key, std::move(v));
    return *this;
}
Value& Value::oneLine() {
    oneLine_ = true;
    return *this;
}
Value& Value::headerFields(int n) {
    headerFields_ = n;
    return *this;
}

std::vector<std::pair<std::string, const Value*>> Value::orderedFields() const {
    std::vector<std::string> keys;
    for (const auto& f : fields_) keys.push_back(f.first);
    std::vector<std::pair<std::string, const Value*>> out;
    for (const auto& k : js::objectKeyOrder(keys)) {
        for (const auto& f : fields_) {
            if (f.first == k) out.emplace_back(k, &f.second);
        }
    }
    return out;
}

std::string quote(const std::string& utf8) {
    static const char* hex = "0123456789abcdef";
    std::string out = "\"";
    for (char ch : utf8) {
        auto c = static_cast<unsigned char>(ch);
        switch (c) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\b': out += "\\b"; break;
            case '\f': out += "\\f"; break;
            case '\n': out += "\\n"; break;
            case '\r': out += "\\r"; break;
            case '\t': out += "\\t"; break;
            default:
                if (c < 0x20) {
                    out += "\\u00";
                    out += hex[c >> 4];
                    out += hex[c & 15];
                } else {
                    out += ch;
                }
        }
    }
    return out + "\"";
}

std::string Value::compact() const {
    switch (kind_) {
        case Kind::Null: return "null";
        case Kind::Bool: return bool_ ? "true" : "false";
        case Kind::Int: return std::to_string(int_);
        case Kind::String: return quote(string_);
        case Kind::Array: {
            std::string out = "[";
            for (size_t i = 0; i < items_.size(); ++i) out += (i ? "," : "") + items_[i].compact();
            return out + "]";
        }
        case Kind::Object: {
            std::string out = "{";
            bool first = true;
            for (const auto& [k, v] : orderedFields()) {
                out += (first ? "" : ",") + quote(k) + ":" + v->compact();
                first = false;
            }
            return out + "}";
        }
    }
    return "null";
}

std::string Value::pretty() const { return format("", 0, true); }

std::string Value::format(const std::string& indent, size_t prefixLength, bool top) const {
    const std::string flat = compact();
    if (kind_ != Kind::Array && kind_ != Kind::Object) return flat;
    if (!top && (oneLine_ || indent.size() + prefixLength + js::lengthUtf16(flat) <= kWidth)) return flat;
    const std::string inner = indent + "  ";
    if (kind_ == Kind::Array) {
        if (items_.empty()) return "[]";
        std::string out = "[\n";
        for (size_t i = 0; i < items_.size(); ++i) {
            out += inner + items_[i].format(inner, 0, false) + (i + 1 < items_.size() ? ",\n" : "\n");
        }
        return out + indent + "]";
    }
    auto fields = orderedFields();
    if (fields.empty()) return "{}";
    std::vector<std::string> lines;
    size_t start = 0;
    if (headerFields_ > 1) {
        std::string head = inner;
        size_t n = std::min(fields.size(), static_cast<size_t>(headerFields_));
        for (size_t i = 0; i < n; ++i) head += (i ? ", " : "") + quote(fields[i].first) + ": " + fields[i].second->compact();
        lines.push_back(head);
        start = n;
    }
    for (size_t i = start; i < fields.size(); ++i) {
        std::string key = quote(fields[i].first) + ": ";
        lines.push_back(inner + key + fields[i].second->format(inner, js::lengthUtf16(key), false));
    }
    std::string out = "{\n";
    for (size_t i = 0; i < lines.size(); ++i) out += lines[i] + (i + 1 < lines.size() ? ",\n" : "\n");
    return out + indent + "}";
}

}  // namespace psc::json
