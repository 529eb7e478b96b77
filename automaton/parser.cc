#include "hybrid/automaton/parser.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <exception>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <system_error>
#include <tao/pegtl.hpp>
#include <tao/pegtl/contrib/limit_depth.hpp>
#include <tao/pegtl/contrib/parse_tree.hpp>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "automaton/quoted_text.h"
#include "automaton/rectangular_rate.h"
#include "automaton/stack_thread.h"

namespace hybrid {

ParseError::ParseError(std::string file, int line, int column, const std::string& message)
    : std::runtime_error(EscapedForMessage(file) + ":" + std::to_string(line) + ":" +
                         std::to_string(column) + ": " + EscapedForMessage(message)),
      file_(std::move(file)),
      line_(line),
      column_(column),
      message_(EscapedForMessage(message)) {}

namespace {
namespace pegtl = tao::pegtl;

// "a variable", "an input", ...
std::string WithArticle(std::string_view noun) {
  const bool vowel =
      !noun.empty() && std::string_view("aeiou").find(noun.front()) != std::string_view::npos;
  return (vowel ? "an " : "a ") + std::string(noun);
}

// ---------------------------------------------------------------------------------------------
// Grammar. Tokens consume the white space and comments that follow them, so every rule starts on
// a significant character.
namespace grammar {
using namespace pegtl;  // NOLINT(google-build-using-namespace): PEGTL's combinators

struct comment : seq<one<'#'>, until<eolf>> {};
struct sp : star<sor<ascii::space, comment>> {};
template <class Rule>
struct tok : seq<Rule, sp> {};

struct ident_first : ranges<'a', 'z', 'A', 'Z', '_'> {};
struct ident_other : ranges<'a', 'z', 'A', 'Z', '0', '9', '_'> {};
template <class Str>
struct key : seq<Str, not_at<ident_other>, sp> {};

struct kw_automaton : key<TAO_PEGTL_STRING("automaton")> {};
struct kw_system : key<TAO_PEGTL_STRING("system")> {};
struct kw_import : key<TAO_PEGTL_STRING("import")> {};
struct kw_var : key<TAO_PEGTL_STRING("var")> {};
struct kw_discrete : key<TAO_PEGTL_STRING("discrete")> {};
struct kw_param : key<TAO_PEGTL_STRING("param")> {};
struct kw_input : key<TAO_PEGTL_STRING("input")> {};
struct kw_mode : key<TAO_PEGTL_STRING("mode")> {};
struct kw_inv : key<TAO_PEGTL_STRING("inv")> {};
struct kw_transition : key<TAO_PEGTL_STRING("transition")> {};
struct kw_guard : key<TAO_PEGTL_STRING("guard")> {};
struct kw_reset : key<TAO_PEGTL_STRING("reset")> {};
struct kw_label : key<TAO_PEGTL_STRING("label")> {};
struct kw_urgent : key<TAO_PEGTL_STRING("urgent")> {};
struct kw_lazy : key<TAO_PEGTL_STRING("lazy")> {};
struct kw_init : key<TAO_PEGTL_STRING("init")> {};
struct kw_scenario : key<TAO_PEGTL_STRING("scenario")> {};
struct kw_until : key<TAO_PEGTL_STRING("until")> {};
struct kw_step : key<TAO_PEGTL_STRING("step")> {};
struct kw_linear : key<TAO_PEGTL_STRING("linear")> {};
struct kw_property : key<TAO_PEGTL_STRING("property")> {};
struct kw_always : key<TAO_PEGTL_STRING("always")> {};
struct kw_never : key<TAO_PEGTL_STRING("never")> {};
struct kw_reach : key<TAO_PEGTL_STRING("reach")> {};
struct kw_within : key<TAO_PEGTL_STRING("within")> {};
struct kw_instance : key<TAO_PEGTL_STRING("instance")> {};
struct kw_share : key<TAO_PEGTL_STRING("share")> {};
struct kw_and : key<TAO_PEGTL_STRING("and")> {};
struct kw_or : key<TAO_PEGTL_STRING("or")> {};
struct kw_not : key<TAO_PEGTL_STRING("not")> {};
struct kw_in : key<TAO_PEGTL_STRING("in")> {};
struct kw_true : key<TAO_PEGTL_STRING("true")> {};
struct kw_false : key<TAO_PEGTL_STRING("false")> {};

struct keyword
    : sor<kw_automaton, kw_system, kw_import, kw_var, kw_discrete, kw_param, kw_input, kw_mode,
          kw_inv, kw_transition, kw_guard, kw_reset, kw_label, kw_urgent, kw_lazy, kw_init,
          kw_scenario, kw_until, kw_step, kw_linear, kw_property, kw_always, kw_never, kw_reach,
          kw_within, kw_instance, kw_share, kw_and, kw_or, kw_not, kw_in, kw_true, kw_false> {};

struct raw_identifier : seq<ident_first, star<ident_other>> {};
struct identifier : seq<not_at<keyword>, raw_identifier> {};
// A possibly qualified name (`A.theta1`).
struct name : seq<identifier, star<one<'.'>, identifier>> {};
struct name_tok : seq<name, sp> {};
struct ident_tok : seq<identifier, sp> {};

struct digits : plus<digit> {};
struct exponent_digits : digits {};
struct exponent : seq<one<'e', 'E'>, opt<one<'+', '-'>>, must<exponent_digits>> {};
struct number
    : seq<sor<seq<digits, opt<one<'.'>, star<digit>>>, seq<one<'.'>, digits>>, opt<exponent>> {};
struct number_tok : seq<number, sp> {};
struct signed_number : seq<opt<one<'+', '-'>>, sp, number> {};
struct signed_number_tok : seq<signed_number, sp> {};

struct semi : tok<one<';'>> {};
struct comma : tok<one<','>> {};
struct colon : tok<one<':'>> {};
struct lbrace : tok<one<'{'>> {};
struct rbrace : tok<one<'}'>> {};
struct lparen : tok<one<'('>> {};
struct rparen : tok<one<')'>> {};
struct lbracket : tok<one<'['>> {};
struct rbracket : tok<one<']'>> {};
struct equals : tok<seq<one<'='>, not_at<one<'='>>>> {};
struct arrow : tok<string<'-', '>'>> {};
struct assign : tok<string<':', '='>> {};
struct prime : tok<one<'\''>> {};

// Expressions.
struct expression;
struct unary;
struct plus_op : tok<one<'+'>> {};
struct minus_op : tok<seq<one<'-'>, not_at<one<'>'>>>> {};
struct times_op : tok<one<'*'>> {};
struct divide_op : tok<one<'/'>> {};
struct power_op : tok<one<'^'>> {};
struct operand : seq<unary> {};
struct arguments : opt<list<expression, comma>> {};
struct call : seq<ident_tok, lparen, arguments, must<rparen>> {};
struct paren_expression : seq<lparen, expression, must<rparen>> {};
struct primary : sor<number_tok, call, name_tok, paren_expression> {};
struct power : seq<primary, opt<power_op, must<operand>>> {};
struct negation : seq<minus_op, must<operand>> {};
struct unary : sor<negation, power> {};
struct product : seq<unary, star<sor<times_op, divide_op>, must<operand>>> {};
struct sum : seq<product, star<sor<plus_op, minus_op>, must<product>>> {};
struct expression : seq<sum> {};

// Comparisons and predicates.
struct relation
    : tok<sor<string<'<', '='>, string<'>', '='>, string<'=', '='>, one<'<'>, one<'>'>>> {};
struct comparison : seq<expression, relation, must<expression>> {};
struct no_or : not_at<kw_or> {};
struct conjunction : sor<kw_true, seq<comparison, star<kw_and, must<comparison>>>> {};
struct predicate;
// An operator or relation after `( ... )` makes the parenthesis part of an expression, so a
// parenthesised predicate must not be followed by one (`(x + 1) >= 0` is a comparison).
struct continues_expression
    : sor<relation, plus_op, minus_op, times_op, divide_op, power_op, one<'='>> {};
struct paren_predicate : seq<lparen, predicate, rparen, not_at<continues_expression>> {};
struct in_mode : seq<kw_in, must<name_tok>> {};
// An expression where a predicate operand was expected (`always x + 1;`): accepted by the grammar
// only where nothing else matches, so that the builder reports it with its text. `x = 1` is
// reported here: '=' is not a comparison.
struct not_single_equals : not_at<equals> {};
struct non_predicate : seq<expression, must<not_single_equals>> {};
struct not_predicate;
struct negated : seq<kw_not, must<not_predicate>> {};
struct not_predicate
    : sor<negated, paren_predicate, in_mode, kw_true, kw_false, comparison, non_predicate> {};
struct and_predicate : seq<not_predicate, star<kw_and, must<not_predicate>>> {};
struct predicate : seq<and_predicate, star<kw_or, must<and_predicate>>> {};

// Declarations.
struct unit_text : plus<sor<ident_other, one<'/', '*', '^', '.', '-'>>> {};
struct unit : seq<lbracket, must<unit_text>, sp, must<rbracket>> {};
struct range : seq<lbracket, must<expression>, must<comma>, must<expression>, must<rbracket>> {};
struct var_item : seq<ident_tok, opt<unit>, opt<kw_in, must<range>>> {};
struct var_decl : seq<kw_var, must<var_item>, star<comma, must<var_item>>, must<semi>> {};
struct discrete_decl : seq<kw_discrete, must<ident_tok>, star<comma, must<ident_tok>>, must<semi>> {
};
struct param_range : seq<kw_in, must<range>> {};
struct param_end : semi {};
struct param_decl : seq<kw_param, must<ident_tok>, opt<unit>, must<equals>, must<expression>,
                        opt<param_range>, must<param_end>> {};
struct input_decl
    : seq<kw_input, must<ident_tok>, opt<unit>, must<kw_in>, must<range>, must<semi>> {};

struct discrete_value : seq<ident_tok, must<equals>, must<signed_number_tok>> {};
struct discrete_values
    : seq<lparen, must<discrete_value>, star<comma, must<discrete_value>>, must<rparen>> {};
struct flow_rhs : sor<seq<equals, must<expression>>, seq<kw_in, must<range>>> {};
struct flow : seq<ident_tok, prime, must<flow_rhs>, must<semi>> {};
struct invariant : seq<kw_inv, must<conjunction>, must<no_or>, must<semi>> {};
struct mode_item : sor<flow, invariant> {};
struct mode_body_end : rbrace {};
struct mode_decl : seq<kw_mode, must<ident_tok>, opt<discrete_values>, must<lbrace>,
                       star<mode_item>, must<mode_body_end>> {};

struct transition_name : seq<ident_tok, colon> {};
struct source_mode : ident_tok {};
struct target_mode : ident_tok {};
struct guard : seq<kw_guard, must<conjunction>, must<no_or>, must<semi>> {};
struct assignment : seq<ident_tok, must<assign>, must<expression>> {};
struct reset : seq<kw_reset, must<assignment>, star<comma, must<assignment>>, must<semi>> {};
struct label : seq<kw_label, must<name_tok>, must<semi>> {};
struct urgency : seq<sor<kw_urgent, kw_lazy>, must<semi>> {};
struct transition_item : sor<guard, reset, label, urgency> {};
struct transition_body_end : rbrace {};
struct transition_decl
    : seq<kw_transition, opt<transition_name>, must<source_mode>, must<arrow>, must<target_mode>,
          must<lbrace>, star<transition_item>, must<transition_body_end>> {};

struct init_point : seq<equals, must<expression>> {};
struct init_range : seq<kw_in, must<range>> {};
struct init_value_kind : sor<init_point, init_range> {};
struct init_item : seq<ident_tok, must<init_value_kind>, must<semi>> {};
struct init_body_end : rbrace {};
struct init_decl
    : seq<kw_init, must<ident_tok>, must<lbrace>, star<init_item>, must<init_body_end>> {};

struct point : seq<signed_number_tok, must<colon>, must<signed_number_tok>> {};
struct points : seq<lparen, must<point>, star<comma, must<point>>, must<rparen>> {};
struct shape : sor<kw_step, kw_linear> {};
struct signal_shape : seq<shape, must<points>> {};
struct signal : sor<signal_shape, signed_number_tok> {};
struct signal_item : seq<name_tok, must<equals>, must<signal>, must<semi>> {};
struct until_item : seq<kw_until, must<signed_number_tok>, must<semi>> {};
struct scenario_item : sor<until_item, signal_item> {};
struct scenario_body_end : rbrace {};
struct scenario_decl
    : seq<kw_scenario, must<lbrace>, star<scenario_item>, must<scenario_body_end>> {};

struct property_kind : sor<kw_always, kw_never, kw_reach> {};
struct horizon : seq<kw_within, must<signed_number_tok>> {};
struct property_decl : seq<kw_property, must<ident_tok>, must<colon>, must<property_kind>,
                           must<predicate>, opt<horizon>, must<semi>> {};

// `label l1, l2;`: labels in the automaton's alphabet that it may have no transition for.
struct label_decl : seq<kw_label, must<name_tok>, star<comma, must<name_tok>>, must<semi>> {};
struct automaton_item : sor<var_decl, discrete_decl, param_decl, input_decl, label_decl, mode_decl,
                            transition_decl, init_decl, scenario_decl, property_decl> {};
struct automaton_body_end : rbrace {};
struct automaton_decl : seq<kw_automaton, must<ident_tok>, must<lbrace>, star<automaton_item>,
                            must<automaton_body_end>> {};

struct instance_alias : seq<equals, must<ident_tok>> {};
// `{ g = A.g; stall = A.stall; }`: names of the automaton bound to names of the system.
struct bind_item : seq<ident_tok, must<equals>, must<name_tok>, must<semi>> {};
struct binds_end : rbrace {};
struct binds : seq<lbrace, star<bind_item>, must<binds_end>> {};
struct instance_end : sor<semi, binds> {};
struct instance_item : seq<kw_instance, must<ident_tok>, opt<instance_alias>, must<instance_end>> {
};
struct share_item : seq<kw_share, must<name_tok>, star<comma, must<name_tok>>, must<semi>> {};
struct system_item : sor<instance_item, share_item, property_decl, scenario_decl> {};
struct system_body_end : rbrace {};
struct system_decl
    : seq<kw_system, must<ident_tok>, must<lbrace>, star<system_item>, must<system_body_end>> {};

struct string_body : star<not_one<'"', '\n', '\r'>> {};
struct close_quote : one<'"'> {};
struct string_literal : seq<one<'"'>, string_body, must<close_quote>, sp> {};
struct import_decl : seq<kw_import, must<string_literal>, must<semi>> {};

struct top_item : sor<import_decl, automaton_decl, system_decl> {};
struct end_of_file : eof {};
struct file : seq<sp, star<top_item>, must<end_of_file>> {};
struct signal_end : eof {};
struct signal_text : seq<sp, must<signal>, must<signal_end>> {};

// Error messages for the rules under must<>.
template <class Rule>
inline constexpr const char* kMessage = nullptr;
template <>
inline constexpr auto kMessage<ident_tok> = "expected a name";
template <>
inline constexpr auto kMessage<name_tok> = "expected a name";
template <>
inline constexpr auto kMessage<source_mode> = "expected the source mode";
template <>
inline constexpr auto kMessage<target_mode> = "expected the target mode";
template <>
inline constexpr auto kMessage<exponent_digits> = "expected digits in the exponent";
template <>
inline constexpr auto kMessage<semi> = "expected ';'";
template <>
inline constexpr auto kMessage<comma> = "expected ','";
template <>
inline constexpr auto kMessage<colon> = "expected ':'";
template <>
inline constexpr auto kMessage<lbrace> = "expected '{'";
template <>
inline constexpr auto kMessage<rparen> = "expected ')'";
template <>
inline constexpr auto kMessage<rbracket> = "expected ']'";
template <>
inline constexpr auto kMessage<equals> = "expected '='";
template <>
inline constexpr auto kMessage<arrow> = "expected '->'";
template <>
inline constexpr auto kMessage<assign> = "expected ':='";
template <>
inline constexpr auto kMessage<expression> = "expected an expression";
template <>
inline constexpr auto kMessage<operand> = "expected an operand";
template <>
inline constexpr auto kMessage<product> = "expected an operand";
template <>
inline constexpr auto kMessage<comparison> =
    "expected a comparison (an expression, one of < <= > >= ==, an expression)";
template <>
inline constexpr auto kMessage<conjunction> =
    "expected a comparison, a conjunction of comparisons ('and'), or 'true'";
template <>
inline constexpr auto kMessage<no_or> =
    "guards and invariants are conjunctions: 'or' is not allowed here (split the transition in "
    "two)";
template <>
inline constexpr auto kMessage<predicate> = "expected a predicate";
template <>
inline constexpr auto kMessage<not_predicate> = "expected a predicate";
template <>
inline constexpr auto kMessage<not_single_equals> =
    "'=' is not a comparison: write '==' for equality";
template <>
inline constexpr auto kMessage<param_end> = "expected ';' or a range 'in [lo, hi]'";
template <>
inline constexpr auto kMessage<and_predicate> = "expected a predicate";
template <>
inline constexpr auto kMessage<unit_text> = "expected a unit such as [deg] or [m/s]";
template <>
inline constexpr auto kMessage<range> = "expected a range '[lo, hi]'";
template <>
inline constexpr auto kMessage<var_item> = "expected a variable name";
template <>
inline constexpr auto kMessage<kw_in> = "expected 'in'";
template <>
inline constexpr auto kMessage<discrete_value> = "expected 'name = integer'";
template <>
inline constexpr auto kMessage<signed_number_tok> = "expected a number";
template <>
inline constexpr auto kMessage<flow_rhs> =
    "expected '= expression' (a flow) or 'in [lo, hi]' (a rectangular rate) after x'";
template <>
inline constexpr auto kMessage<mode_body_end> =
    "expected a flow (x' = expression; or x' in [lo, hi];), an invariant (inv ...;) or '}' closing "
    "the mode";
template <>
inline constexpr auto kMessage<transition_body_end> =
    "expected 'guard', 'reset', 'label', 'urgent', 'lazy' or '}' closing the transition";
template <>
inline constexpr auto kMessage<assignment> = "expected an assignment 'x := expression'";
template <>
inline constexpr auto kMessage<init_value_kind> = "expected '= value' or 'in [lo, hi]'";
template <>
inline constexpr auto kMessage<init_body_end> =
    "expected an initial value (x = value; or x in [lo, hi];) or '}'";
template <>
inline constexpr auto kMessage<point> = "expected a point 'time: value'";
template <>
inline constexpr auto kMessage<points> = "expected '(' and points 'time: value'";
template <>
inline constexpr auto kMessage<signal> =
    "expected a signal: a number, step(t: v, ...) or linear(t: v, ...)";
template <>
inline constexpr auto kMessage<scenario_body_end> =
    "expected 'until T;', 'input = signal;' or '}' closing the scenario";
template <>
inline constexpr auto kMessage<property_kind> = "expected 'always', 'never' or 'reach'";
template <>
inline constexpr auto kMessage<automaton_body_end> =
    "expected a declaration (var, discrete, param, input, mode, transition, init, scenario, "
    "property) or '}' closing the automaton";
template <>
inline constexpr auto kMessage<system_body_end> =
    "expected 'instance', 'share', 'property', 'scenario' or '}' closing the system";
template <>
inline constexpr auto kMessage<instance_end> = "expected ';' or '{' binding names (x = A.y;)";
template <>
inline constexpr auto kMessage<binds_end> = "expected a bind 'x = A.y;' or '}'";
template <>
inline constexpr auto kMessage<string_literal> = "expected a quoted file name";
template <>
inline constexpr auto kMessage<close_quote> = "unterminated string";
template <>
inline constexpr auto kMessage<signal_end> = "unexpected text after the signal";
template <>
inline constexpr auto kMessage<end_of_file> =
    "expected 'automaton', 'system' or 'import' at top level";

// Messages are used only when a rule under must<> fails (raise_on_failure is false), so a rule
// may also appear in ordered choices where failing is normal.
struct errors {
  template <class Rule>
  static constexpr const char* message = kMessage<Rule>;
  template <class Rule>
  static constexpr bool raise_on_failure = false;
};

template <class Rule>
using control = must_if<errors, normal, false>::control<Rule>;

// Rules kept in the parse tree. Everything else is folded away.
template <class Rule>
using selector = parse_tree::selector<
    Rule,
    parse_tree::store_content::on<identifier, name, unit_text, number, signed_number, relation,
                                  plus_op, minus_op, times_op, divide_op, string_body, kw_urgent,
                                  kw_lazy, kw_step, kw_linear, kw_always, kw_never, kw_reach,
                                  kw_true, kw_false>,
    parse_tree::remove_content::on<
        call, negation, comparison, conjunction, paren_predicate, in_mode, negated, non_predicate,
        param_range, unit, range, var_item, var_decl, discrete_decl, param_decl, input_decl,
        label_decl, discrete_value, flow, invariant, mode_decl, transition_name, source_mode,
        target_mode, guard, assignment, reset, label, urgency, transition_decl, init_point,
        init_range, init_item, init_decl, point, signal_shape, until_item, signal_item,
        scenario_decl, horizon, property_decl, automaton_decl, instance_alias, bind_item, binds,
        instance_item, share_item, system_decl, import_decl, power, arguments>,
    parse_tree::fold_one::on<sum, product, and_predicate, predicate>>;

template <class Rule>
struct depth_action : limit_depth<1000> {};

}  // namespace grammar

using Node = pegtl::parse_tree::node;

// A location in the model text (line and column from 1, columns in bytes), copied out of the
// parse tree. A node's begin() would hold a view of the input's source name, so it is never
// used: only these plain numbers are kept.
struct SourcePosition {
  int line = 0;
  int column = 0;
};

SourcePosition Where(const Node& n) {
  return {static_cast<int>(n.m_begin.line), static_cast<int>(n.m_begin.column)};
}

// ---------------------------------------------------------------------------------------------
// Building the model from the parse tree.

// The imports of one model: the files being imported (a chain from the top-level file, to find
// cycles), the files imported so far with the automata they define (each file is read once,
// however many imports reach it), and the bytes read, which the model's size limit bounds.
struct Imports {
  std::set<std::filesystem::path> active;
  std::map<std::filesystem::path, std::map<std::string, Automaton>> done;
  std::size_t bytes = 0;
};

// The transition names of one automaton, and the default names of its unnamed transitions:
// `SRC_to_DST` for the first, then the first of `SRC_to_DST_2`, `SRC_to_DST_3`, ... that no
// earlier transition has (named or not). Names are only ever added, so the first free number
// of a base never decreases: each base keeps where its search stopped, and every name is passed
// over at most twice (as a base, and as a base with a number), so naming N transitions takes
// O(N) look-ups in all.
class TransitionNames {
 public:
  // The default name of the next unnamed transition from `base` (SRC_to_DST).
  std::string Default(const std::string& base) {
    int& k = next_number_[base];  // 0 the first time: try `base` itself
    std::string name = k < 2 ? base : base + "_" + std::to_string(k);
    while (taken_.count(name) != 0) {
      k = std::max(k, 1) + 1;
      name = base + "_" + std::to_string(k);
    }
    return name;
  }
  // Records the name of a transition added to the automaton.
  void Taken(const std::string& name) { taken_.insert(name); }

 private:
  std::unordered_set<std::string> taken_;
  std::unordered_map<std::string, int> next_number_;  // base -> the number its search is at
};

class Builder {
 public:
  Builder(std::string file, Imports* imports) : file_(std::move(file)), imports_(imports) {}

  [[noreturn]] void Fail(const Node& n, const std::string& message) const {
    Fail(Where(n), message);
  }
  [[noreturn]] void Fail(const SourcePosition& at, const std::string& message) const {
    throw ParseError(file_, at.line, at.column, message);
  }

  // Runs `f`; an std::invalid_argument from the model API (whose messages speak of the model)
  // becomes a ParseError at `n`.
  template <class F>
  auto At(const Node& n, F&& f) -> decltype(f()) {
    try {
      return f();
    } catch (const std::invalid_argument& e) {
      Fail(n, e.what());
    }
  }

  void File(const Node& root) {
    for (const auto& item : root.children) {
      if (item->is_type<grammar::import_decl>()) {
        Import(*item);
      } else if (item->is_type<grammar::automaton_decl>()) {
        AutomatonDecl(*item);
      } else if (item->is_type<grammar::system_decl>()) {
        if (system_) Fail(*item, "a file may declare at most one system");
        SystemDecl(*item);
      }
    }
  }

  System Result(const Node& root) {
    if (system_) return std::move(*system_);
    if (local_automata_.size() == 1) return System::Of(automata_.at(local_automata_.front()));
    if (local_automata_.empty()) Fail(root, "the file declares no automaton and no system");
    // Point at the second automaton: the first one alone would have been the model.
    Fail(local_positions_.at(1),
         "the file declares " + std::to_string(local_automata_.size()) +
             " automata and no system: add 'system NAME { instance A = a; ... }'");
  }

  const std::map<std::string, Automaton>& automata() const { return automata_; }
  const std::vector<std::string>& local_automata() const { return local_automata_; }
  bool has_system() const { return system_.has_value(); }

 private:
  // Symbol resolution context: an automaton being built, or a system, and the kinds of symbol
  // its expressions may read besides parameters.
  struct Scope {
    const SymbolTable* symbols;
    bool allow_state = true;  // continuous and discrete variables
    bool allow_inputs = true;
    // Why a symbol is not allowed (the end of the message).
    const char* rule = "";
  };
  // Parameter values, domains, input bounds and initial values: parameters only.
  static Scope ConstantScope(const SymbolTable& symbols) {
    return {&symbols, false, false,
            "a parameter value, domain, bound or initial value may read only parameters"};
  }
  // Properties: the state and parameters, not inputs.
  static Scope PropertyScope(const SymbolTable& symbols) {
    return {&symbols, true, false, "a property may not read inputs"};
  }

  static std::string Text(const Node& n) { return n.string(); }

  double Number(const Node& n) const {
    // A signed number is a sign, white space or comments, then its `number` child.
    if (n.is_type<grammar::signed_number>()) {
      const double magnitude = Number(*n.children.at(0));
      return n.string_view().front() == '-' ? -magnitude : magnitude;
    }
    const std::string text = n.string();
    double value = 0.0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec == std::errc::result_out_of_range || !std::isfinite(value)) {
      Fail(n, "number '" + text + "' is out of range");
    }
    if (ec != std::errc() || end != text.data() + text.size()) Fail(n, "malformed number");
    return value;
  }

  // The message for an expression or predicate deeper than kMaxExpressionDepth.
  static std::string TooDeep() {
    return "expression too long or nested too deeply (more than " +
           std::to_string(kMaxExpressionDepth) + " levels)";
  }

  // `e`, built at `n`; fails at `n` if it is deeper than kMaxExpressionDepth. Every node is
  // checked as it is built, so the error points at the operator that crosses the limit and no
  // tree deeper than the limit plus one level is ever built.
  template <class Tree>
  Tree Checked(const Node& n, Tree e) const {
    if (e.depth() > kMaxExpressionDepth) Fail(n, TooDeep());
    return e;
  }

  // Builds the expression of `n`.
  Expression Expr(const Node& n, const Scope& scope) const {
    using namespace grammar;  // NOLINT(google-build-using-namespace)
    if (n.is_type<number>()) return Expression::Constant(Number(n));
    if (n.is_type<name>()) {
      const std::string id = Text(n);
      const auto slot = scope.symbols->Find(id);
      if (!slot) Fail(n, "undefined name '" + id + "'");
      const SymbolKind kind = (*scope.symbols)[*slot].kind;
      const bool state = kind == SymbolKind::kVariable || kind == SymbolKind::kDiscrete;
      if ((state && !scope.allow_state) || (kind == SymbolKind::kInput && !scope.allow_inputs)) {
        Fail(n, std::string(KindName(kind)) + " '" + id + "' is not allowed here: " + scope.rule);
      }
      return Expression::Symbol(id, *slot);
    }
    if (n.is_type<negation>()) return Checked(n, -Expr(*n.children.back(), scope));
    if (n.is_type<power>()) {
      Expression base = Expr(*n.children.at(0), scope);
      if (n.children.size() == 1) return base;
      return Checked(n, Expression::Binary(Op::kPow, base, Expr(*n.children.at(1), scope)));
    }
    if (n.is_type<call>()) return Call(n, scope);
    if (n.is_type<sum>() || n.is_type<product>()) {
      // Left-associative: a long sum is a deep tree, one level per operator.
      Expression acc = Expr(*n.children.at(0), scope);
      for (size_t i = 1; i + 1 < n.children.size(); i += 2) {
        const Node& op = *n.children[i];
        Expression rhs = Expr(*n.children[i + 1], scope);
        if (op.is_type<plus_op>())
          acc = Checked(op, acc + rhs);
        else if (op.is_type<minus_op>())
          acc = Checked(op, acc - rhs);
        else if (op.is_type<times_op>())
          acc = Checked(op, acc * rhs);
        else
          acc = Checked(op, acc / rhs);
      }
      return acc;
    }
    Fail(n, "internal error: unexpected expression node " + std::string(n.type));
  }

  // A function call `f(args)`.
  Expression Call(const Node& n, const Scope& scope) const {
    const std::string fn = Text(*n.children.at(0));
    std::vector<Expression> args;
    if (n.children.size() > 1) {
      for (const auto& a : n.children.at(1)->children) args.push_back(Expr(*a, scope));
    }
    const auto op = FunctionByName(fn, static_cast<int>(args.size()));
    if (!op) {
      if (FunctionByName(fn, 1) || FunctionByName(fn, 2)) {
        Fail(n, "function '" + fn + "' takes " + (FunctionByName(fn, 1) ? "1" : "2") +
                    " argument(s), not " + std::to_string(args.size()));
      }
      Fail(n, "unknown function '" + fn + "'");
    }
    return Checked(n, args.size() == 1 ? Expression::Unary(*op, args[0])
                                       : Expression::Binary(*op, args[0], args[1]));
  }

  // A comparison; its residual lhs - rhs (one level above the deeper side) must be within
  // kMaxExpressionDepth, checked at the relation.
  Comparison Compare(const Node& n, const Scope& scope) const {
    const Node& relation = *n.children.at(1);
    const std::string rel = Text(relation);
    Relation r = Relation::kEqual;
    if (rel.starts_with("<="))
      r = Relation::kLessEqual;
    else if (rel.starts_with(">="))
      r = Relation::kGreaterEqual;
    else if (rel.starts_with("=="))
      r = Relation::kEqual;
    else if (rel.starts_with("<"))
      r = Relation::kLess;
    else if (rel.starts_with(">"))
      r = Relation::kGreater;
    Expression lhs = Expr(*n.children.at(0), scope);
    Expression rhs = Expr(*n.children.at(2), scope);
    if (std::max(lhs.depth(), rhs.depth()) + 1 > kMaxExpressionDepth) Fail(relation, TooDeep());
    return {std::move(lhs), r, std::move(rhs)};
  }

  Constraint Conjunction(const Node& n, const Scope& scope) const {
    Constraint c;
    for (const auto& child : n.children) {
      if (child->is_type<grammar::comparison>()) c.comparisons.push_back(Compare(*child, scope));
    }
    return c;
  }

  // The predicate of property `property` (named in messages).
  Predicate Pred(const Node& n, const Scope& scope,
                 const std::function<bool(const std::string&)>& is_mode,
                 const std::string& property) const {
    using namespace grammar;  // NOLINT(google-build-using-namespace)
    if (n.is_type<non_predicate>()) {
      const Expression e = Expr(*n.children.at(0), scope);
      Fail(n, "property '" + property + "': '" + e.ToString() +
                  "' is not a predicate (expected a comparison such as x >= 0, 'in MODE', true or "
                  "false)");
    }
    if (n.is_type<kw_true>()) return Predicate::True();
    if (n.is_type<kw_false>()) return Predicate::False();
    if (n.is_type<comparison>()) return Predicate::Compare(Compare(n, scope));
    if (n.is_type<in_mode>()) {
      const std::string m = Text(*n.children.at(0));
      if (!is_mode(m)) Fail(*n.children.at(0), "unknown mode '" + m + "'");
      return Predicate::InMode(m);
    }
    if (n.is_type<negated>()) {
      return Checked(n, Predicate::Not(Pred(*n.children.at(0), scope, is_mode, property)));
    }
    if (n.is_type<paren_predicate>()) return Pred(*n.children.at(0), scope, is_mode, property);
    if (n.is_type<and_predicate>() || n.is_type<predicate>()) {
      // Left-associative, like sums.
      Predicate acc = Pred(*n.children.at(0), scope, is_mode, property);
      for (size_t i = 1; i < n.children.size(); ++i) {
        Predicate rhs = Pred(*n.children[i], scope, is_mode, property);
        acc = Checked(*n.children[i], n.is_type<and_predicate>() ? Predicate::And(acc, rhs)
                                                                 : Predicate::Or(acc, rhs));
      }
      return acc;
    }
    Fail(n, "internal error: unexpected predicate node " + std::string(n.type));
  }

  std::string Unit(const Node& parent) const {
    for (const auto& c : parent.children) {
      if (c->is_type<grammar::unit>()) return Text(*c->children.at(0));
    }
    return "";
  }

  const Node* Child(const Node& parent, auto rule_tag) const {
    using Rule = decltype(rule_tag);
    for (const auto& c : parent.children) {
      if (c->template is_type<Rule>()) return c.get();
    }
    return nullptr;
  }

  Range RangeOf(const Node& n, const Scope& scope) const {
    return {Expr(*n.children.at(0), scope), Expr(*n.children.at(1), scope)};
  }

  // The right-hand side of flow `item` (whose variable is declared in `a`): its expression, or
  // for `x' in [lo, hi]` the RectangularFlow over x's rate input (declared with x).
  Expression FlowOf(const Node& item, const Automaton& a, const Scope& scope) {
    const Node& rhs = *item.children.at(1);
    if (!rhs.is_type<grammar::range>()) return Expr(rhs, scope);
    const Range rate = RangeOf(rhs, scope);
    const double lo = At(*rhs.children.at(0), [&] { return a.EvaluateConstant(rate.lo, "rate"); });
    const double hi = At(*rhs.children.at(1), [&] { return a.EvaluateConstant(rate.hi, "rate"); });
    if (lo > hi) {
      Fail(rhs, "empty rate range: " + FormatNumber(lo) + " > " + FormatNumber(hi));
    }
    const std::string w = RateInputName(Text(*item.children.at(0)));
    return RectangularFlow(rate, Expression::Symbol(w, *a.symbols().Find(w)));
  }

  // Names of the variables some mode of automaton declaration `n` gives a rectangular rate.
  static std::set<std::string> RatedVariables(const Node& n) {
    std::set<std::string> rated;
    for (const auto& item : n.children) {
      if (!item->is_type<grammar::mode_decl>()) continue;
      for (const auto& flow : item->children) {
        if (flow->is_type<grammar::flow>() && flow->children.at(1)->is_type<grammar::range>()) {
          rated.insert(Text(*flow->children.at(0)));
        }
      }
    }
    return rated;
  }

  int Slot(const Node& n, const Automaton& a, SymbolKind kind, std::string_view what) const {
    const std::string id = Text(n);
    const auto slot = a.symbols().Find(id);
    if (!slot) Fail(n, "undefined " + std::string(what) + " '" + id + "'");
    if (a.symbols()[*slot].kind != kind) {
      Fail(n, "'" + id + "' is " + WithArticle(KindName(a.symbols()[*slot].kind)) + ", not " +
                  WithArticle(what));
    }
    return *slot;
  }

  ModeId ModeOf(const Node& n, const Automaton& a) const {
    const std::string id = Text(n);
    const auto m = a.FindMode(id);
    if (!m) Fail(n, "unknown mode '" + id + "'");
    return *m;
  }

  Property PropertyOf(const Node& n, const Scope& scope,
                      const std::function<bool(const std::string&)>& is_mode) const {
    Property p;
    p.name = Text(*n.children.at(0));
    const Node& kind = *n.children.at(1);
    p.kind = kind.is_type<grammar::kw_always>()  ? Property::Kind::kAlways
             : kind.is_type<grammar::kw_never>() ? Property::Kind::kNever
                                                 : Property::Kind::kReach;
    p.predicate = Pred(*n.children.at(2), scope, is_mode, p.name);
    if (n.children.size() > 3) p.horizon = Number(*n.children.at(3)->children.at(0));
    return p;
  }

  // `bounds(slot)` gives the evaluated bounds of the input at `slot`.
  // The shape and points of a `signal` node; `check_value` is called on every value.
  InputSignal SignalOf(const Node& value,
                       const std::function<void(const Node&, double)>& check_value) const {
    InputSignal sig;
    if (value.is_type<grammar::signed_number>()) {
      sig.points = {{0.0, Number(value)}};
      check_value(value, sig.points[0].second);
      return sig;
    }
    sig.shape = value.children.at(0)->is_type<grammar::kw_linear>() ? InputSignal::Shape::kLinear
                                                                    : InputSignal::Shape::kStep;
    for (size_t i = 1; i < value.children.size(); ++i) {
      const Node& p = *value.children[i];
      const double t = Number(*p.children.at(0));
      if (!sig.points.empty() && !(sig.points.back().first < t)) {
        Fail(p, "signal times must increase strictly");
      }
      const Node& v = *p.children.at(1);
      sig.points.emplace_back(t, Number(v));
      check_value(v, sig.points.back().second);
    }
    return sig;
  }

 public:
  // A signal alone (command-line `--input NAME=SIGNAL`).
  InputSignal StandaloneSignal(const Node& root) const {
    return SignalOf(*root.children.at(0), [](const Node&, double) {});
  }

 private:
  Scenario ScenarioOf(const Node& n, const SymbolTable& symbols,
                      const std::function<std::pair<double, double>(int)>& bounds) const {
    Scenario s;
    bool has_until = false;
    std::unordered_set<int> driven;
    for (const auto& item : n.children) {
      if (item->is_type<grammar::until_item>()) {
        if (has_until) Fail(*item, "'until' given twice");
        has_until = true;
        s.until = Number(*item->children.at(0));
        if (!(s.until > 0.0)) Fail(*item->children.at(0), "'until' must be positive");
        continue;
      }
      InputSignal sig;
      const Node& input = *item->children.at(0);
      const auto slot = symbols.Find(Text(input));
      if (!slot) Fail(input, "undefined input '" + Text(input) + "'");
      if (symbols[*slot].kind != SymbolKind::kInput) {
        Fail(input, "'" + Text(input) + "' is " + WithArticle(KindName(symbols[*slot].kind)) +
                        ", not an input");
      }
      if (!driven.insert(*slot).second) Fail(input, "input '" + Text(input) + "' driven twice");
      sig.slot = *slot;
      // Plain variables, not a structured binding: clang before 16 cannot capture structured
      // bindings in a lambda (a C++20 feature).
      const std::pair<double, double> input_bounds = bounds(*slot);
      const double lo = input_bounds.first, hi = input_bounds.second;
      const Node& value = *item->children.at(1);
      InputSignal shaped = SignalOf(value, [&](const Node& v, double x) {
        if (x < lo || x > hi) {
          Fail(v, "signal for '" + Text(input) + "' takes value " + FormatNumber(x) +
                      " outside its bounds [" + FormatNumber(lo) + ", " + FormatNumber(hi) + "]");
        }
      });
      sig.shape = shaped.shape;
      sig.points = std::move(shaped.points);
      s.inputs.push_back(std::move(sig));
    }
    if (!has_until) Fail(n, "scenario needs 'until T;'");
    return s;
  }

  void AutomatonDecl(const Node& n) {
    using namespace grammar;  // NOLINT(google-build-using-namespace)
    const Node& name_node = *n.children.at(0);
    const std::string name = Text(name_node);
    if (automata_.count(name)) Fail(name_node, "duplicate automaton '" + name + "'");
    Automaton a(name);
    bool has_scenario = false;
    std::vector<const Node*> inits;  // the mode name of each init declaration, in order
    const std::set<std::string> rated = RatedVariables(n);
    TransitionNames transition_names;
    for (size_t i = 1; i < n.children.size(); ++i) {
      const Node& item = *n.children[i];
      if (SymbolDecl(item, rated, &a)) continue;
      if (item.is_type<label_decl>()) {
        for (const auto& id : item.children) At(*id, [&] { a.DeclareLabel(Text(*id)); });
      } else if (item.is_type<mode_decl>()) {
        ModeDecl(item, &a);
      } else if (item.is_type<transition_decl>()) {
        TransitionDecl(item, &a, &transition_names);
      } else if (item.is_type<init_decl>()) {
        InitDecl(item, &a);
        inits.push_back(item.children.at(0).get());
      } else if (item.is_type<scenario_decl>()) {
        if (has_scenario) Fail(item, "scenario declared twice");
        has_scenario = true;
        AutomatonScenario(item, &a);
      } else if (item.is_type<property_decl>()) {
        Property p = PropertyOf(item, PropertyScope(a.symbols()),
                                [&](const std::string& m) { return a.FindMode(m).has_value(); });
        At(*item.children.at(0), [&] { a.AddProperty(std::move(p)); });
      }
    }
    if (a.num_modes() == 0) Fail(name_node, "automaton '" + name + "' has no modes");
    if (a.initial_states().empty()) {
      Fail(name_node, "automaton '" + name + "' has no initial state (add 'init MODE { ... }')");
    }
    CheckInitialStatesComplete(a, inits);
    automata_.emplace(name, std::move(a));
    local_automata_.push_back(name);
    local_positions_.push_back(Where(name_node));
  }

  // Declares the symbols of `item` in `a` if it is a var, discrete, param or input declaration
  // (`rated`: the variables some mode gives a rectangular rate); returns whether it was.
  bool SymbolDecl(const Node& item, const std::set<std::string>& rated, Automaton* a) {
    using namespace grammar;  // NOLINT(google-build-using-namespace)
    const Scope scope = ConstantScope(a->symbols());
    if (item.is_type<var_decl>()) {
      for (const auto& v : item.children) {
        const Node& id = *v->children.at(0);
        std::optional<Range> domain;
        if (const Node* r = Child(*v, range{})) domain = RangeOf(*r, scope);
        At(id, [&] { return a->AddVariable(Text(id), Unit(*v), domain); });
        if (rated.count(Text(id))) DeclareRateInput(*a, Text(id));
      }
    } else if (item.is_type<discrete_decl>()) {
      for (const auto& id : item.children) {
        At(*id, [&] { return a->AddDiscreteVariable(Text(*id)); });
      }
    } else if (item.is_type<param_decl>()) {
      // Children: the name, the unit if any, the value, the range if any.
      const Node& id = *item.children.at(0);
      const size_t value_index = item.children.at(1)->is_type<unit>() ? 2 : 1;
      const Expression value = Expr(*item.children.at(value_index), scope);
      std::optional<Range> declared;
      if (const Node* r = Child(item, param_range{})) declared = RangeOf(*r->children.at(0), scope);
      At(id, [&] { return a->AddParameter(Text(id), value, Unit(item), declared); });
    } else if (item.is_type<input_decl>()) {
      const Node& id = *item.children.at(0);
      const Range bounds = RangeOf(*Child(item, range{}), scope);
      At(id, [&] { return a->AddInput(Text(id), bounds, Unit(item)); });
    } else {
      return false;
    }
    return true;
  }

  // The scenario `n` of automaton `a`.
  void AutomatonScenario(const Node& n, Automaton* a) {
    std::vector<double> parameters;  // evaluated once, at the first input driven
    Scenario s = ScenarioOf(n, a->symbols(), [&](int slot) {
      if (parameters.empty()) parameters = a->ParameterEnvironment();
      // The inputs are in slot order; their bounds were checked finite when declared.
      const auto in = std::lower_bound(a->inputs().begin(), a->inputs().end(), slot,
                                       [](const InputInfo& x, int s) { return x.slot < s; });
      return std::make_pair(in->bounds.lo.Evaluate(parameters), in->bounds.hi.Evaluate(parameters));
    });
    At(n, [&] { a->SetScenario(std::move(s)); });
  }

  void ModeDecl(const Node& n, Automaton* a) {
    using namespace grammar;  // NOLINT(google-build-using-namespace)
    const Scope scope{&a->symbols()};
    const Node& name_node = *n.children.at(0);
    Mode m;
    m.name = Text(name_node);
    std::unordered_set<int> given;  // slots with a flow or a discrete value so far
    for (size_t i = 1; i < n.children.size(); ++i) {
      const Node& item = *n.children[i];
      if (item.is_type<discrete_value>()) {
        const Node& id = *item.children.at(0);
        const int slot = Slot(id, *a, SymbolKind::kDiscrete, "discrete variable");
        const double v = Number(*item.children.at(1));
        if (v != std::nearbyint(v) || std::abs(v) > 1e9) {
          Fail(*item.children.at(1), "discrete values must be integers");
        }
        if (!given.insert(slot).second) Fail(id, "discrete variable '" + Text(id) + "' set twice");
        m.discrete_values.emplace_back(slot, static_cast<int>(v));
      } else if (item.is_type<flow>()) {
        const Node& id = *item.children.at(0);
        const int slot = Slot(id, *a, SymbolKind::kVariable, "continuous variable");
        if (!given.insert(slot).second) {
          Fail(id, "second flow for '" + Text(id) + "' in mode '" + m.name + "'");
        }
        m.flows.emplace_back(slot, FlowOf(item, *a, scope));
      } else if (item.is_type<invariant>()) {
        for (Comparison& c : Conjunction(*item.children.at(0), scope).comparisons) {
          m.invariant.comparisons.push_back(std::move(c));
        }
      }
    }
    std::sort(m.flows.begin(), m.flows.end(),
              [](const auto& x, const auto& y) { return x.first < y.first; });
    std::sort(m.discrete_values.begin(), m.discrete_values.end());
    At(name_node, [&] { return a->AddMode(std::move(m)); });
  }

  void TransitionDecl(const Node& n, Automaton* a, TransitionNames* names) {
    using namespace grammar;  // NOLINT(google-build-using-namespace)
    const Scope scope{&a->symbols()};
    Transition t;
    size_t i = 0;
    const Node* name_node = nullptr;
    if (n.children.at(0)->is_type<transition_name>()) {
      name_node = n.children.at(0)->children.at(0).get();
      ++i;
    }
    const Node& source = *n.children.at(i)->children.at(0);
    const Node& target = *n.children.at(i + 1)->children.at(0);
    t.source = ModeOf(source, *a);
    t.target = ModeOf(target, *a);
    // Default name: source_to_target, numbered when repeated.
    t.name = name_node ? Text(*name_node) : names->Default(Text(source) + "_to_" + Text(target));
    bool has_guard = false, has_label = false, has_urgency = false;
    std::unordered_set<int> reset_slots;
    for (size_t j = i + 2; j < n.children.size(); ++j) {
      const Node& item = *n.children[j];
      if (item.is_type<guard>()) {
        if (has_guard) Fail(item, "second 'guard' (conjoin the comparisons with 'and')");
        has_guard = true;
        t.guard = Conjunction(*item.children.at(0), scope);
      } else if (item.is_type<reset>()) {
        for (const auto& as : item.children) {
          const Node& id = *as->children.at(0);
          const int slot = Slot(id, *a, SymbolKind::kVariable, "continuous variable");
          if (!reset_slots.insert(slot).second) Fail(id, "'" + Text(id) + "' reset twice");
          t.resets.push_back({slot, Expr(*as->children.at(1), scope)});
        }
      } else if (item.is_type<label>()) {
        if (has_label) Fail(item, "second 'label'");
        has_label = true;
        t.label = Text(*item.children.at(0));
      } else if (item.is_type<urgency>()) {
        if (has_urgency) Fail(item, "urgency given twice");
        has_urgency = true;
        t.urgency = item.children.at(0)->is_type<kw_lazy>() ? Urgency::kLazy : Urgency::kUrgent;
      }
    }
    std::sort(t.resets.begin(), t.resets.end(),
              [](const Reset& x, const Reset& y) { return x.slot < y.slot; });
    const std::string name = t.name;
    At(name_node ? *name_node : source, [&] { return a->AddTransition(std::move(t)); });
    names->Taken(name);
  }

  // Every initial state gives every continuous variable a value, also those declared after it
  // (AddInitialState checked only the variables declared before). `inits[k]` is the mode name
  // of the k-th initial state's declaration.
  void CheckInitialStatesComplete(const Automaton& a, const std::vector<const Node*>& inits) const {
    const auto states = a.initial_states();
    for (size_t k = 0; k < states.size() && k < inits.size(); ++k) {
      for (const VariableInfo& var : a.variables()) {
        // The values are sorted by slot (InitDecl).
        const auto it =
            std::lower_bound(states[k].values.begin(), states[k].values.end(), var.slot,
                             [](const InitialValue& v, int slot) { return v.slot < slot; });
        const bool given = it != states[k].values.end() && it->slot == var.slot;
        if (!given) {
          Fail(*inits[k], "initial state in '" + Text(*inits[k]) + "' gives no value for '" +
                              a.symbols()[var.slot].name + "', declared after it");
        }
      }
    }
  }

  void InitDecl(const Node& n, Automaton* a) {
    const Scope scope = ConstantScope(a->symbols());
    const Node& mode_node = *n.children.at(0);
    InitialState s;
    s.mode = ModeOf(mode_node, *a);
    std::unordered_set<int> given;
    for (size_t i = 1; i < n.children.size(); ++i) {
      const Node& item = *n.children[i];
      const Node& id = *item.children.at(0);
      const int slot = Slot(id, *a, SymbolKind::kVariable, "continuous variable");
      if (!given.insert(slot).second) Fail(id, "initial value of '" + Text(id) + "' given twice");
      const Node& value = *item.children.at(1);
      InitialValue v;
      v.slot = slot;
      if (value.is_type<grammar::init_point>()) {
        const Expression e = Expr(*value.children.at(0), scope);
        v.range = {e, e};
      } else {
        v.range = RangeOf(*value.children.at(0), scope);
        v.is_point = false;
      }
      s.values.push_back(std::move(v));
    }
    std::sort(s.values.begin(), s.values.end(),
              [](const InitialValue& x, const InitialValue& y) { return x.slot < y.slot; });
    At(mode_node, [&] { a->AddInitialState(std::move(s)); });
  }

  // `instance A = automaton;`, `instance automaton;`, either with `{ x = B.y; ... }`.
  void InstanceItem(const Node& item, System& s) {
    const Node& first = *item.children.at(0);
    std::string instance;
    const Node* automaton_node = &first;
    std::map<std::string, std::string> binds;
    for (size_t i = 1; i < item.children.size(); ++i) {
      const Node& child = *item.children[i];
      if (child.is_type<grammar::instance_alias>()) {
        instance = Text(first);
        automaton_node = child.children.at(0).get();
        continue;
      }
      for (const auto& bind : child.children) {
        const Node& from = *bind->children.at(0);
        if (!binds.emplace(Text(from), Text(*bind->children.at(1))).second) {
          Fail(from, "'" + Text(from) + "' bound twice");
        }
      }
    }
    auto it = automata_.find(Text(*automaton_node));
    if (it == automata_.end()) {
      Fail(*automaton_node, "unknown automaton '" + Text(*automaton_node) + "'");
    }
    try {
      s.AddComponent(instance, it->second, std::move(binds));
    } catch (const ConflictError& e) {
      // Both declarations: this instance, and the earlier one it contradicts.
      const SourcePosition other = instance_positions_.at(static_cast<size_t>(e.other_component()));
      Fail(first, std::string(e.what()) + " (the other declaration: " + file_ + ":" +
                      std::to_string(other.line) + ":" + std::to_string(other.column) + ")");
    } catch (const std::invalid_argument& e) {
      Fail(first, e.what());
    }
    instance_positions_.push_back(Where(first));
  }

  void SystemDecl(const Node& n) {
    using namespace grammar;  // NOLINT(google-build-using-namespace)
    const Node& name_node = *n.children.at(0);
    System s(Text(name_node));
    bool has_scenario = false;
    for (size_t i = 1; i < n.children.size(); ++i) {
      const Node& item = *n.children[i];
      if (item.is_type<share_item>()) {
        if (!s.components().empty()) Fail(item, "'share' must come before the first 'instance'");
        for (const auto& id : item.children) s.Share(Text(*id));
      } else if (item.is_type<instance_item>()) {
        InstanceItem(item, s);
      } else if (item.is_type<property_decl>()) {
        if (s.components().empty()) Fail(item, "declare the instances before the properties");
        Property p = PropertyOf(item, PropertyScope(s.symbols()),
                                [&](const std::string& m) { return s.FindMode(m).has_value(); });
        At(*item.children.at(0), [&] { s.AddProperty(std::move(p)); });
      } else if (item.is_type<scenario_decl>()) {
        if (has_scenario) Fail(item, "scenario declared twice");
        has_scenario = true;
        Scenario sc = ScenarioOf(item, s.symbols(), [&](int slot) { return s.InputBounds(slot); });
        At(item, [&] { s.SetScenario(std::move(sc)); });
      }
    }
    if (s.components().empty()) Fail(name_node, "system '" + s.name() + "' has no instances");
    system_ = std::move(s);
  }

  void Import(const Node& n);
  // Adds the automata an import defines (the same automaton reached twice is fine).
  void Merge(const Node& n, const std::map<std::string, Automaton>& automata);

  std::string file_;
  Imports* imports_;
  std::map<std::string, Automaton> automata_;
  std::vector<std::string> local_automata_;
  // Where each of local_automata_ is declared (its name), as plain numbers: nothing taken from the
  // parse tree may outlive it.
  std::vector<SourcePosition> local_positions_;
  // Where each instance of the system being built is declared, in component order.
  std::vector<SourcePosition> instance_positions_;
  std::optional<System> system_;
};

[[noreturn]] void CannotRead(const std::filesystem::path& path, const std::string& why) {
  throw ParseError(path.string(), 0, 0, "cannot read file: " + why);
}

// `size` is "N bytes" when known.
[[noreturn]] void TooLarge(const std::filesystem::path& path, const std::string& size) {
  throw ParseError(path.string(), 0, 0,
                   "file is " + (size.empty() ? "" : size + ", ") + "larger than the " +
                       std::to_string(kMaxModelFileBytes) + "-byte limit for model files");
}

// The whole content of the model file `path`, read as a stream so that pipes, FIFOs and
// /dev/stdin work like regular files. A regular file's size is checked before reading; any other
// file is read up to the limit.
std::string ReadFile(const std::filesystem::path& path) {
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (ec) CannotRead(path, ec.message());
  if (std::filesystem::is_directory(status)) CannotRead(path, "it is a directory");
  if (std::filesystem::is_regular_file(status)) {
    const auto size = std::filesystem::file_size(path, ec);
    if (ec) CannotRead(path, ec.message());
    if (size > kMaxModelFileBytes) TooLarge(path, std::to_string(size) + " bytes");
  }
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) CannotRead(path, errno != 0 ? std::generic_category().message(errno) : "cannot open it");
  std::string text;
  char chunk[1 << 16];
  while (in.read(chunk, sizeof(chunk)) || in.gcount() > 0) {
    text.append(chunk, static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxModelFileBytes) TooLarge(path, "");
  }
  if (in.bad())
    CannotRead(path, errno != 0 ? std::generic_category().message(errno) : "read error");
  return text;
}

// A parse tree with the input it was parsed from. Nodes hold views into the input (of its text
// and of its source name), so the input lives exactly as long as the tree: `input` is declared
// first and destroyed last. The text itself belongs to the caller and must outlive both.
struct ParsedText {
  std::unique_ptr<pegtl::memory_input<>> input;
  std::unique_ptr<Node> tree;
};

// The UTF-8 encoding of U+FEFF, which some editors write at the start of a file.
constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";

// Parses `text` with grammar rule `Rule` into a parse tree; every failure is a ParseError. A
// leading byte-order mark is skipped (columns of line 1 count from after it).
template <class Rule>
ParsedText ParseTree(std::string_view text, const std::string& file_name) {
  if (text.starts_with(kByteOrderMark)) text.remove_prefix(kByteOrderMark.size());
  // Binary input: report the first NUL or control byte precisely instead of a grammar error.
  int line = 1, column = 1;
  for (unsigned char c : text) {
    if (c == 0 || (c < 0x20 && c != '\n' && c != '\r' && c != '\t' && c != '\f' && c != '\v')) {
      throw ParseError(
          file_name, line, column,
          c == 0 ? "NUL byte in model file (binary file?)"
                 : "control character " + std::to_string(c) + " in model file (binary file?)");
    }
    if (c == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  ParsedText parsed;
  parsed.input = std::make_unique<pegtl::memory_input<>>(text.data(), text.size(), file_name);
  try {
    parsed.tree =
        pegtl::parse_tree::parse<Rule, grammar::selector, grammar::depth_action, grammar::control>(
            *parsed.input);
  } catch (const pegtl::parse_error& e) {
    const auto& pos = e.positions().front();
    std::string message(e.message());
    if (message.find("nesting depth") != std::string::npos) {
      message = "expression nested too deeply";
    } else if (message.find("parse error matching") != std::string::npos) {
      message = "syntax error";
    }
    throw ParseError(file_name, static_cast<int>(pos.line), static_cast<int>(pos.column), message);
  }
  if (!parsed.tree) throw ParseError(file_name, 1, 1, "syntax error");
  return parsed;
}

// Parses `text` into `*parsed` and builds it with `builder`.
void ParseInto(std::string_view text, const std::string& file_name, Builder* builder,
               ParsedText* parsed) {
  *parsed = ParseTree<grammar::file>(text, file_name);
  builder->File(*parsed->tree);
}

void Builder::Import(const Node& n) {
  const std::string relative = Text(*n.children.at(0));
  std::filesystem::path path = std::filesystem::path(file_).parent_path() / relative;
  std::error_code ec;
  const auto canonical = std::filesystem::weakly_canonical(path, ec);
  if (ec || !std::filesystem::is_regular_file(canonical)) {
    Fail(n, "cannot import '" + relative + "': no such file");
  }
  if (imports_->active.count(canonical) != 0) {
    Fail(n, "import cycle through '" + relative + "'");
  }
  // A file imported before (by another import) is not read again: what it defines is known.
  if (const auto done = imports_->done.find(canonical); done != imports_->done.end()) {
    Merge(n, done->second);
    return;
  }
  imports_->active.insert(canonical);
  // The top-level file is in the set too.
  if (static_cast<int>(imports_->active.size()) > kMaxImportDepth + 1) {
    Fail(n, "imports nested more than " + std::to_string(kMaxImportDepth) + " files deep");
  }
  std::string text;
  try {
    text = ReadFile(path);
  } catch (const ParseError& e) {
    Fail(n, "cannot import '" + relative + "': " + e.message());
  }
  imports_->bytes += text.size();
  if (imports_->bytes > kMaxModelFileBytes) {
    Fail(n, "cannot import '" + relative + "': the model and its imports are larger than the " +
                std::to_string(kMaxModelFileBytes) + "-byte limit for models");
  }
  const std::string imported_name = path.string();
  Builder imported(imported_name, imports_);
  ParsedText parsed;
  ParseInto(text, imported_name, &imported, &parsed);  // errors point into the imported file
  imports_->active.erase(canonical);
  const auto& automata = imports_->done.emplace(canonical, imported.automata()).first->second;
  Merge(n, automata);
}

void Builder::Merge(const Node& n, const std::map<std::string, Automaton>& automata) {
  for (const auto& [name, automaton] : automata) {
    if (auto it = automata_.find(name); it != automata_.end()) {
      // The same automaton reached twice (a file imported by two imports) is fine.
      if (!(it->second == automaton)) Fail(n, "import redefines automaton '" + name + "'");
      continue;
    }
    automata_.emplace(name, automaton);
  }
}

// The stack the parser runs on, whatever its caller's. PEGTL's rules and the tree builder recurse
// once per level of nesting (about 7 rules per parenthesis), up to the grammar's limit
// (grammar::depth_action) and kMaxImportDepth imports; at that bound a parse takes under 4 MiB of
// stack even under AddressSanitizer (tests/automaton/parser_test.cc checks the nesting limit on a
// 1 MiB caller stack). Only the pages touched are committed.
constexpr std::size_t kParserStackBytes = std::size_t{64} << 20;

// The thread with a kParserStackBytes stack that parses for the calling thread: made on its first
// parse, reused by every later one, ended with it.
StackThread& ParserThread() {
  thread_local StackThread thread(kParserStackBytes);
  return thread;
}

// Runs `f` on ParserThread(); returns its result or rethrows what it throws. Runs `f` here if
// already on such a stack (an import parsed during a parse) or if no thread can be made.
template <class F>
auto OnParserStack(F f) -> decltype(f()) {
  if (StackThread::CurrentStackBytes() >= kParserStackBytes) return f();
  StackThread& thread = ParserThread();
  if (!thread.running()) return f();
  std::optional<decltype(f())> result;
  thread.Run([&] { result.emplace(f()); });
  return std::move(*result);
}

// The imports of a top-level file of `bytes` bytes: the file itself is active, so that
// importing it is a cycle.
Imports TopLevelImports(const std::string& file_name, std::size_t bytes) {
  Imports imports;
  imports.bytes = bytes;
  std::error_code ec;
  const auto canonical = std::filesystem::weakly_canonical(file_name, ec);
  if (ec || !std::filesystem::is_regular_file(canonical, ec)) return imports;
  imports.active.insert(canonical);
  return imports;
}

}  // namespace

System ParseModel(std::string_view text, const std::string& file_name) {
  return OnParserStack([&] {
    Imports imports = TopLevelImports(file_name, text.size());
    Builder builder(file_name, &imports);
    ParsedText parsed;
    ParseInto(text, file_name, &builder, &parsed);
    return builder.Result(*parsed.tree);
  });
}

std::string ReadModelText(const std::filesystem::path& path) { return ReadFile(path); }

System ParseModelFile(const std::filesystem::path& path) {
  return ParseModel(ReadFile(path), path.string());
}

Automaton ParseAutomaton(std::string_view text, const std::string& file_name) {
  return OnParserStack([&] {
    Imports imports = TopLevelImports(file_name, text.size());
    Builder builder(file_name, &imports);
    ParsedText parsed;
    ParseInto(text, file_name, &builder, &parsed);
    if (builder.has_system() || builder.local_automata().size() != 1) {
      throw ParseError(file_name, 1, 1, "expected exactly one automaton and no system");
    }
    return builder.automata().at(builder.local_automata().front());
  });
}

InputSignal ParseSignal(std::string_view text, const std::string& source_name) {
  return OnParserStack([&] {
    const ParsedText parsed = ParseTree<grammar::signal_text>(text, source_name);
    Imports none;
    const Builder builder(source_name, &none);
    return builder.StandaloneSignal(*parsed.tree);
  });
}

}  // namespace hybrid
