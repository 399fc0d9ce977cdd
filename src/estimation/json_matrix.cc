#include "estimation/json_matrix.h"

#include <vector>

#include "common/short_text.h"

namespace recruit::estimation::json_io {

namespace {

// One SAX pass that builds the tree (nlohmann's own DOM builder) while it tracks the field path
// and the depth: a document nested too deep stops before its tree does, and nlohmann's errors
// become messages (returning false stops the parser at once). It replaced a checking pass
// followed by a parse, which read each filter model twice.
class CheckingSax final : public nlohmann::json_sax<nlohmann::json> {
 public:
  explicit CheckingSax(nlohmann::json* out) : dom_(*out, /*allow_exceptions=*/false) {}
  std::string error;

  bool null() override { return Value() && dom_.null(); }
  bool boolean(bool b) override { return Value() && dom_.boolean(b); }
  bool number_integer(number_integer_t x) override { return Value() && dom_.number_integer(x); }
  bool number_unsigned(number_unsigned_t x) override { return Value() && dom_.number_unsigned(x); }
  bool number_float(number_float_t x, const string_t& s) override {
    return Value() && dom_.number_float(x, s);
  }
  bool string(string_t& s) override { return Value() && dom_.string(s); }
  bool binary(binary_t& b) override { return Value() && dom_.binary(b); }
  bool start_object(std::size_t n) override { return Open(false) && dom_.start_object(n); }
  bool key(string_t& k) override {
    stack_.back().key = k;
    return dom_.key(k);
  }
  bool end_object() override { return Close() && dom_.end_object(); }
  bool start_array(std::size_t n) override { return Open(true) && dom_.start_array(n); }
  bool end_array() override { return Close() && dom_.end_array(); }
  bool parse_error(std::size_t position, const std::string& last_token,
                   const nlohmann::detail::exception& ex) override {
    if (ex.id == 406) {  // out_of_range: number overflow
      error = Field() + "number '" + ShortText(last_token) +
              "' is too large for a double (finite numbers only)";
    } else {
      std::string what = ex.what();
      // nlohmann echoes the last token ("last read: '...'"); keep ~40 characters of it.
      const size_t lr = what.find("last read: '");
      if (lr != std::string::npos) {
        std::string tok = what.substr(lr + 12);
        if (!tok.empty() && tok.back() == '\'') tok.pop_back();
        what = what.substr(0, lr + 12) + ShortText(tok) + "'";
      }
      error = "malformed JSON: " + Field() + what;
    }
    (void)position;
    return false;
  }

 private:
  struct Frame {
    bool array;
    size_t index = 0;
    std::string key;
  };
  bool Value() {
    if (!stack_.empty() && stack_.back().array) ++stack_.back().index;
    return true;
  }
  bool Open(bool array) {
    if (static_cast<int>(stack_.size()) >= kMaxJsonDepth) {
      error = Field() + "nested deeper than " + std::to_string(kMaxJsonDepth) +
              " levels (a filter model nests at most 4)";
      return false;
    }
    stack_.push_back({array, 0, ""});
    return true;
  }
  bool Close() {
    stack_.pop_back();
    return Value();
  }
  // "field a.b[2]: " for the value being read, or "" at the top level.
  std::string Field() const {
    std::string f;
    for (const Frame& fr : stack_) {
      if (fr.array) {
        f += "[" + std::to_string(fr.index) + "]";
      } else if (!fr.key.empty()) {
        f += (f.empty() ? "" : ".") + ShortText(fr.key);
      }
    }
    return f.empty() ? "" : "field " + f + ": ";
  }
  std::vector<Frame> stack_;
  nlohmann::detail::json_sax_dom_parser<nlohmann::json> dom_;
};

}  // namespace

Result<nlohmann::json> ParseJson(const std::string& text, const std::string& path) {
  nlohmann::json j;
  CheckingSax sax(&j);
  if (!nlohmann::json::sax_parse(text, &sax) || !sax.error.empty()) {
    return Error{path + ": " + (sax.error.empty() ? "malformed JSON" : sax.error)};
  }
  return j;
}

nlohmann::json WriteMatrix(const Eigen::MatrixXd& M) {
  nlohmann::json j = nlohmann::json::array();
  for (Eigen::Index i = 0; i < M.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index k = 0; k < M.cols(); ++k) row.push_back(M(i, k));
    j.push_back(row);
  }
  return j;
}

nlohmann::json WriteVector(const Eigen::VectorXd& v) {
  nlohmann::json j = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) j.push_back(v(i));
  return j;
}

}  // namespace recruit::estimation::json_io
