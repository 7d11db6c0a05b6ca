// SPDX-License-Identifier: BSD-3-Clause
// One field table per Parameters struct: names, units, ranges and access
// (docs/style.md §2.5).
#pragma once

#include <dynvo/common/export.h>

#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace dynvo {

/// How a field's value is spelled in a configuration file and on the command line.
enum class FieldKind {
  integer, ///< a whole number
  real,    ///< a number
  boolean, ///< 0 or 1
  choice   ///< one of FieldInfo::choices (an enum class with values 0, 1, ...)
};

/** \brief The values one field accepts: finite, within [lo, hi] where each end may be open
 * (excluded) and either may be infinite (no bound). Integer fields also need a whole number
 * that fits their type.
 */
struct DYNVO_EXPORTS FieldRange {
  double lo = -std::numeric_limits<double>::infinity(); ///< lower bound
  double hi = std::numeric_limits<double>::infinity();  ///< upper bound
  bool lo_open = false;                                 ///< true: lo itself is excluded
  bool hi_open = false;                                 ///< true: hi itself is excluded

  /// Any finite value.
  static FieldRange any() { return {}; }
  /// value >= lo
  static FieldRange atLeast(double lo) { return {lo, any().hi, false, false}; }
  /// value > lo
  static FieldRange above(double lo) { return {lo, any().hi, true, false}; }
  /// lo <= value <= hi
  static FieldRange closed(double lo, double hi) { return {lo, hi, false, false}; }

  /// True when value is finite and within the bounds.
  bool contains(double value) const;

  /// The rule in words, e.g. ">= 2", "> 0", "in [1, 254]", "in (0, 1]".
  std::string describe() const;
};

/// Shortest text that reads back as the same value ("16", "0.03", "3e-05"); with
/// single_precision, the same float (a float field's 0.03f is "0.03", not "0.0299999993").
DYNVO_EXPORTS std::string formatFieldValue(double value, bool single_precision = false);

/** \brief One field of a Parameters struct.
 *
 * Values travel as double: every int, std::uint32_t, float, bool and enum value of a
 * Parameters struct is exactly representable, so a value read back is the value written.
 */
template <typename Struct> struct FieldInfo {
  std::string
      name; ///< path in the struct, also the key in files: "cell_size", "depth.min_depth"
  std::string doc; ///< symbol and unit for help texts, e.g. "w_grid, px"
  FieldKind kind = FieldKind::real; ///< how the value is spelled
  bool single_precision = false;    ///< a float field (for formatFieldValue())
  FieldRange range;                 ///< accepted values (for a choice: its index)
  std::vector<std::string> choices; ///< names of the values 0, 1, ... (kind == choice)
  std::function<double(const Struct&)> get; ///< the field's value (choice: its index)
  std::function<void(Struct&, double)> set; ///< stores a value accepted by problem()
  /// Empty when value is acceptable for the field's type and range, else why not.
  std::function<std::string(double)> problem;

  /// The index of the choice spelled text (its value for set()), or -1 when there is none.
  int choiceIndex(const std::string& text) const
  {
    for (std::size_t k = 0; k < choices.size(); ++k)
      if (choices[k] == text)
        return static_cast<int>(k);
    return -1;
  }

  /// The value of the field in s, spelled as in a configuration file ("16", "local").
  std::string text(const Struct& s) const
  {
    const double value = get(s);
    return kind == FieldKind::choice ? choices.at(static_cast<std::size_t>(value))
                                     : formatFieldValue(value, single_precision);
  }
};

namespace detail {

/// Why value does not fit a field of type T with the given range, or empty when it does.
template <typename T>
std::string
fieldProblem(double value, const FieldRange& range)
{
  if constexpr (std::is_integral_v<T>) {
    if (!(std::isfinite(value) && value == std::floor(value) &&
          value >= static_cast<double>(std::numeric_limits<T>::lowest()) &&
          value <= static_cast<double>(std::numeric_limits<T>::max())))
      return "must be a whole number " + range.describe() + ", got " +
             formatFieldValue(value);
  }
  // Checked as stored, so that a float rounding to 0 is not accepted as "> 0".
  const double stored =
      std::isfinite(value) ? static_cast<double>(static_cast<T>(value)) : value;
  if (!range.contains(stored))
    return "must be " + range.describe() + ", got " +
           formatFieldValue(value, std::is_same_v<T, float>);
  return {};
}

/// Counts the members of an aggregate (see ParameterTable's constructor).
struct AnyField {
  template <typename T> operator T() const; // declared only: unevaluated use
};

template <typename Struct, typename = void, typename... Fields>
struct AggregateFieldCount
    : std::integral_constant<std::size_t, sizeof...(Fields) - 1> {
};

template <typename Struct, typename... Fields>
struct AggregateFieldCount<Struct,
                           std::void_t<decltype(Struct{std::declval<Fields>()...})>,
                           Fields...>
    : AggregateFieldCount<Struct, void, Fields..., AnyField> {
};

} // namespace detail

/** \brief Number of members of an aggregate struct (a nested struct counts once).
 * Used to prove at compile time that a table lists every field of its struct.
 */
template <typename Struct>
constexpr std::size_t AGGREGATE_FIELD_COUNT =
    detail::AggregateFieldCount<Struct, void, detail::AnyField>::value;

/// A numeric or boolean field bound to a member (see ParameterTable).
template <typename Struct, typename T>
FieldInfo<Struct>
makeField(const std::string& name,
          T Struct::*member,
          FieldRange range,
          const std::string& doc)
{
  static_assert(std::is_arithmetic_v<T>, "use makeChoiceField for enums");
  FieldInfo<Struct> field;
  field.name = name;
  field.doc = doc;
  field.kind = std::is_same_v<T, bool>
                   ? FieldKind::boolean
                   : (std::is_integral_v<T> ? FieldKind::integer : FieldKind::real);
  field.single_precision = std::is_same_v<T, float>;
  field.range = std::is_same_v<T, bool> ? FieldRange::closed(0, 1) : range;
  field.get = [member](const Struct& s) {
    return static_cast<double>(s.*member);
  };
  field.set = [member](Struct& s, double value) {
    s.*member = static_cast<T>(value);
  };
  field.problem = [range = field.range](double value) {
    return detail::fieldProblem<T>(value, range);
  };
  return field;
}

/// An enum class field whose values 0, 1, ... are spelled choices[0], choices[1], ...
template <typename Struct, typename E>
FieldInfo<Struct>
makeChoiceField(const std::string& name,
                E Struct::*member,
                std::vector<std::string> choices,
                const std::string& doc)
{
  static_assert(std::is_enum_v<E>, "makeChoiceField is for enums");
  using Index = std::underlying_type_t<E>;
  FieldInfo<Struct> field;
  field.name = name;
  field.doc = doc;
  field.kind = FieldKind::choice;
  field.range = FieldRange::closed(0, static_cast<double>(choices.size()) - 1);
  field.choices = std::move(choices);
  field.get = [member](const Struct& s) {
    return static_cast<double>(static_cast<Index>(s.*member));
  };
  field.set = [member](Struct& s, double value) {
    s.*member = static_cast<E>(static_cast<Index>(value));
  };
  field.problem = [range = field.range](double value) {
    return detail::fieldProblem<Index>(value, range);
  };
  return field;
}

/// The fields of a nested struct (member of Outer), renamed "prefix.name".
template <typename Outer, typename Inner>
std::vector<FieldInfo<Outer>>
nestFields(const std::string& prefix,
           Inner Outer::*member,
           const std::vector<FieldInfo<Inner>>& fields)
{
  std::vector<FieldInfo<Outer>> nested;
  for (const FieldInfo<Inner>& f : fields) {
    FieldInfo<Outer> n;
    n.name = prefix + "." + f.name;
    n.doc = f.doc;
    n.kind = f.kind;
    n.single_precision = f.single_precision;
    n.range = f.range;
    n.choices = f.choices;
    n.get = [member, get = f.get](const Outer& s) {
      return get(s.*member);
    };
    n.set = [member, set = f.set](Outer& s, double value) {
      set(s.*member, value);
    };
    n.problem = f.problem;
    nested.push_back(std::move(n));
  }
  return nested;
}

/** \brief The single list of a Parameters struct's fields, in file order. It drives the
 * per-field range checks (setters and validate()), configuration files and help texts;
 * cross-field rules stay in validate().
 * \code
 * // in the struct's .cpp
 * const ParameterTable<MyParameters>&
 * MyParameters::table()
 * {
 *   static const ParameterTable<MyParameters> table{
 *       {makeField("cell_size", &MyParameters::cell_size, FieldRange::atLeast(2), "px")}};
 *   return table;
 * }
 * \endcode
 */
template <typename Struct> class ParameterTable {
public:
  using Field = FieldInfo<Struct>;

  /// \param[in] fields every field once, in file order; nested structs via nestFields()
  explicit ParameterTable(std::vector<Field> fields)
      : fields_(std::move(fields))
  {
  }

  /// Concatenates lists of fields (e.g. own fields around nestFields()).
  explicit ParameterTable(std::initializer_list<std::vector<Field>> parts)
  {
    for (const auto& part : parts)
      fields_.insert(fields_.end(), part.begin(), part.end());
  }

  const std::vector<Field>& fields() const { return fields_; }

  /// \throws std::logic_error when the table has no field of that name (a programming error)
  const Field& field(const std::string& name) const
  {
    for (const Field& f : fields_)
      if (f.name == name)
        return f;
    throw std::logic_error("[dynvo::ParameterTable::field] no field '" + name + "'");
  }

  /// \throws std::invalid_argument("prefix name must be ..., got ...") naming the first
  ///         field, in table order, that is out of its own range in s
  void checkAll(const Struct& s, const std::string& prefix) const
  {
    for (const Field& f : fields_)
      check(f, s, prefix);
  }

private:
  static void check(const Field& f, const Struct& s, const std::string& prefix)
  {
    const std::string problem = f.problem(f.get(s));
    if (!problem.empty())
      throw std::invalid_argument(prefix + " " + f.name + " " + problem);
  }

  std::vector<Field> fields_;
};

} // namespace dynvo

/** \brief Declares setName(value) and getName() for the field `field` (a path such as
 * `cell_size` or `depth.min_depth`) of the class's `Parameters params_`.
 *
 * The setter checks the ranges of Parameters::table() and throws
 * std::invalid_argument("[dynvo::<class>::setName] field must be ..., got ...") keeping the
 * old value; then it calls the class's assignParameters(updated). Every other field is in its
 * range already (setParameters() and the setters keep it so), so only the new value can
 * fail. Rules that tie several fields (Parameters::validate()) are checked when the
 * parameters are used, so setters work in any order. The class provides getClassName(),
 * params_ and assignParameters().
 */
#define DYNVO_PARAMETER_ACCESSORS(Name, field)                                         \
  void set##Name(decltype(std::declval<Parameters&>().field) value)                    \
  {                                                                                    \
    Parameters updated = params_;                                                      \
    updated.field = value;                                                             \
    Parameters::table().checkAll(updated, "[dynvo::" + this->getClassName() +          \
                                              "::set" #Name "]");                      \
    assignParameters(updated);                                                         \
  }                                                                                    \
  decltype(std::declval<Parameters&>().field) get##Name() const                        \
  {                                                                                    \
    return params_.field;                                                              \
  }
