// Values from JSON files (model configs, dataset manifests, prediction.json) without
// nlohmann's lossy conversions: get<int>() of 2.5 truncates and of 1e30 is undefined
// behaviour. json_value<T> accepts for an integer T only a whole number within T's range
// (element by element for a std::vector), and throws std::runtime_error otherwise; callers
// name the file and key. Header only.
#pragma once

#include <nlohmann/json.hpp>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <vector>

namespace gdsr {

template <class T> struct is_std_vector : std::false_type {};
template <class T> struct is_std_vector<std::vector<T>> : std::true_type {};

template <class T> T json_value(const nlohmann::json& v) {
  if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
    const bool number = v.is_number_integer() || v.is_number_unsigned() || v.is_number_float();
    const double d = number ? v.get<double>() : 0.0;
    if (!number || std::floor(d) != d || d < static_cast<double>(std::numeric_limits<T>::min()) ||
        d > static_cast<double>(std::numeric_limits<T>::max()))
      throw std::runtime_error("expected a whole number in range, got " + v.dump());
    if (v.is_number_float()) return static_cast<T>(d);
    return v.get<T>();
  } else if constexpr (is_std_vector<T>::value) {
    if (!v.is_array()) throw std::runtime_error("expected a list, got " + v.dump());
    T out;
    for (const auto& e : v) out.push_back(json_value<typename T::value_type>(e));
    return out;
  } else {
    return v.get<T>();
  }
}

}  // namespace gdsr
