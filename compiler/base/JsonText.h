// A JSON value with layout hints, written the way the corpus' compiled-IR
// files are: a value stays on one line when that line fits in 110 columns,
// otherwise its members go one per line; some values are always one line;
// some objects keep their first few members on one line.  Object keys are
// listed in JavaScript order (array-index keys first).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace psc::json {

class Value {
public:
    enum class Kind { Null, Bool, Int, String, Array, Object };

    Value() = default;
    static Value null() { return Value(); }
    static Value boolean(bool b);
    static Value integer(int64_t i);
    static Value string(std::string s);
    static Value array();
    static Value object();

    Value& push(Value v);                          // arrays
    Value& set(const std::string& key, Value v);   // objects, insertion order
    Value& oneLine();                              // always printed on one line
    Value& headerFields(int n);                    // first n members share a line

    Kind kind() const { return kind_; }
    bool empty() const { return items_.empty() && fields_.empty(); }

    std::string compact() const;                   // JSON.stringify(value)
    std::string pretty() const;                    // the layout described above

private:
    std::string format(const std::string& indent, size_t prefixLength, bool top) const;
    std::vector<std::pair<std::string, const Value*>> orderedFields() const;

    Kind kind_ = Kind::Null;
    bool bool_ = false;
    int64_t int_ = 0;
    std::string string_;
    std::vector<Value> items_;
    std::vector<std::pair<std::string, Value>> fields_;
    bool oneLine_ = false;
    int headerFields_ = 0;
};

std::string quote(const std::string& utf8);  // a JSON string literal, as JSON.stringify writes it

}  // namespace psc::json
