#pragma once
// The lights of a scene, stored by strategy: one array per shape x strategy
// (the alternatives of `light`, render/light.hpp), and per light its
// alternative and its place in that array, in 4 bytes. A light takes the
// bytes of its own sampler (80 for a triangle sampled by area) and not
// those of the largest alternative, which a std::vector<light> would give
// every light (sizeof(light) is 800: the ellipse's `auto` sampler). Access
// is one more load than the variant's (the 4-byte entry, from an array
// 1/20 the size of the samplers'), then the same chain of compares
// (core/dispatch.hpp).
//
// A light is reached through a light_ref, which the functions of light.hpp
// (faces, sample, pdf, strategy_of, surface_area) and light_importance.hpp
// take as they take a `light` (light_handle). Changing a light's
// strategy (set) leaves a hole in its old array, which compact() reclaims;
// set, push_back and compact invalidate references into the arrays, as a
// vector's reallocation does.
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <iterator>
#include <span>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "mcrt/render/light.hpp"

namespace mcrt {

template <class Variant>
class basic_light_list;

template <class... S>
class basic_light_list<std::variant<S...>> {
  static_assert(sizeof...(S) <= 32, "the alternative takes the entry's top 5 bits");

 public:
  using value_type = std::variant<S...>;
  static constexpr std::uint32_t slot_bits = 27;
  static constexpr std::uint32_t slot_mask = (std::uint32_t{1} << slot_bits) - 1u;
  static constexpr std::size_t max_size = slot_mask;

  // Light k of a list: what the free functions take (light.hpp). It names
  // the light by its index, so it holds while the list lives, through
  // set(), push_back() and compact(); what visit() hands f does not.
  class reference {
   public:
    reference(const basic_light_list& list, std::uint32_t k) : list_(&list), k_(k) {}
    // The alternative of `light` it holds, as std::variant::index().
    std::size_t index() const { return list_->entries_[k_] >> slot_bits; }
    std::size_t position() const { return k_; }
    // f(the strategy), as std::visit; the alternatives are tested in the
    // variant's order, as core/dispatch.hpp does.
    template <class F>
    decltype(auto) visit(F&& f) const {
      return list_->visit_entry(list_->entries_[k_], static_cast<F&&>(f));
    }

   private:
    const basic_light_list* list_;
    std::uint32_t k_;
  };

  class const_iterator {
   public:
    using reference = basic_light_list::reference;  // a light_ref, by value
    using value_type = reference;
    using iterator_category = std::forward_iterator_tag;
    using difference_type = std::ptrdiff_t;
    using pointer = void;
    const_iterator() = default;
    const_iterator(const basic_light_list* l, std::size_t k) : list_(l), k_(k) {}
    reference operator*() const { return (*list_)[k_]; }
    const_iterator& operator++() { return ++k_, *this; }
    const_iterator operator++(int) { const_iterator t = *this; ++k_; return t; }
    friend bool operator==(const const_iterator& a, const const_iterator& b) { return a.k_ == b.k_; }

   private:
    const basic_light_list* list_ = nullptr;
    std::size_t k_ = 0;
  };

  basic_light_list() = default;
  basic_light_list(std::initializer_list<value_type> ls) {
    for (const value_type& l : ls) push_back(l);
  }

  std::size_t size() const { return entries_.size(); }
  bool empty() const { return entries_.empty(); }
  reference operator[](std::size_t k) const { return reference(*this, static_cast<std::uint32_t>(k)); }
  reference at(std::size_t k) const {
    if (k >= size()) throw std::out_of_range("light_list::at: no light " + std::to_string(k));
    return (*this)[k];
  }
  reference back() const { return (*this)[size() - 1]; }
  const_iterator begin() const { return {this, 0}; }
  const_iterator end() const { return {this, size()}; }

  // Appends a light: a strategy, or a `light` holding one.
  template <class T>
  void push_back(T&& l) {
    if (size() >= max_size) throw std::length_error("light_list: more than 2^27 - 1 lights");
    entries_.push_back(store(static_cast<T&&>(l)));
  }
  template <class T>
  void emplace_back(T&& l) { push_back(static_cast<T&&>(l)); }

  // Light k's strategy, when it is a T (else nullptr, as std::get_if).
  template <class T>
  const T* get_if(std::size_t k) const {
    constexpr std::size_t i = alternative_of<T>();
    const std::uint32_t e = entries_.at(k);
    return (e >> slot_bits) == i ? &std::get<i>(stores_)[e & slot_mask] : nullptr;
  }
  // Light k's strategy, a T (else std::bad_variant_access, as std::get).
  template <class T>
  const T& get(std::size_t k) const {
    if (const T* p = get_if<T>(k)) return *p;
    throw std::bad_variant_access();
  }

  // Makes light k l (a strategy, or a `light`). The same alternative is
  // assigned in place; another is appended to its own array, and the old
  // one's place becomes a hole until compact().
  template <class T>
  void set(std::size_t k, T&& l) {
    const std::uint32_t e = entries_.at(k);
    if (index_of(l) == (e >> slot_bits)) {
      assign(e, static_cast<T&&>(l));
      return;
    }
    ++holes_[e >> slot_bits];
    entries_[k] = store(static_cast<T&&>(l));
  }

  // Moves light k out (no copy of what it shares, such as an `auto`
  // sampler's tables); light k is left moved-from until set() gives it a
  // light again.
  value_type take(std::size_t k) {
    const std::uint32_t e = entries_.at(k);
    return take_entry(e);
  }

  // Drops every hole set() left. Entries keep their lights; references into
  // the arrays do not hold across it.
  void compact() {
    for (std::size_t i = 0; i < sizeof...(S); ++i)
      if (holes_[i] > 0) compact(i);
  }

  // The bytes the lights take: the arrays' capacity and the entries'.
  std::size_t bytes() const {
    std::size_t b = entries_.capacity() * sizeof(std::uint32_t);
    std::apply([&](const auto&... v) { ((b += v.capacity() * sizeof(typename std::decay_t<decltype(v)>::value_type)), ...); },
               stores_);
    return b;
  }

  // Frees capacity beyond the lights held (after a scene is loaded).
  void shrink_to_fit() {
    compact();
    entries_.shrink_to_fit();
    std::apply([](auto&... v) { (v.shrink_to_fit(), ...); }, stores_);
  }

 private:
  template <class T, std::size_t I = 0>
  static constexpr std::size_t alternative_of() {
    static_assert(I < sizeof...(S), "not a strategy of the light variant");
    if constexpr (std::is_same_v<T, std::variant_alternative_t<I, value_type>>)
      return I;
    else
      return alternative_of<T, I + 1>();
  }
  template <class T>
  static std::size_t index_of(const T& l) {
    if constexpr (std::is_same_v<std::decay_t<T>, value_type>)
      return l.index();
    else
      return alternative_of<std::decay_t<T>>();
  }

  template <std::size_t I = 0, class F>
  decltype(auto) visit_entry(std::uint32_t e, F&& f) const {
    const auto& store = std::get<I>(stores_);
    if constexpr (I + 1 == sizeof...(S)) {
      return f(store[e & slot_mask]);
    } else {
      if ((e >> slot_bits) == I) return f(store[e & slot_mask]);
      return visit_entry<I + 1>(e, static_cast<F&&>(f));
    }
  }

  // Appends l to its alternative's array; returns its entry.
  template <class T>
  std::uint32_t store(T&& l) {
    if constexpr (std::is_same_v<std::decay_t<T>, value_type>) {
      return std::visit([&]<class A>(A&& s) { return store(static_cast<A&&>(s)); }, static_cast<T&&>(l));
    } else {
      constexpr std::size_t i = alternative_of<std::decay_t<T>>();
      auto& v = std::get<i>(stores_);
      if (v.size() > slot_mask) throw std::length_error("light_list: more than 2^27 lights of one strategy");
      v.push_back(static_cast<T&&>(l));
      return static_cast<std::uint32_t>(i << slot_bits) | static_cast<std::uint32_t>(v.size() - 1);
    }
  }
  template <class T>
  void assign(std::uint32_t e, T&& l) {
    if constexpr (std::is_same_v<std::decay_t<T>, value_type>) {
      std::visit([&]<class A>(A&& s) { assign(e, static_cast<A&&>(s)); }, static_cast<T&&>(l));
    } else {
      constexpr std::size_t i = alternative_of<std::decay_t<T>>();
      std::get<i>(stores_)[e & slot_mask] = static_cast<T&&>(l);
    }
  }

  template <std::size_t I = 0>
  value_type take_entry(std::uint32_t e) {
    auto& v = std::get<I>(stores_);
    if constexpr (I + 1 == sizeof...(S)) {
      return value_type(std::in_place_index<I>, std::move(v[e & slot_mask]));
    } else {
      if ((e >> slot_bits) == I) return value_type(std::in_place_index<I>, std::move(v[e & slot_mask]));
      return take_entry<I + 1>(e);
    }
  }
  // Rebuilds array i with its live strategies only, in the lights' order.
  template <std::size_t I = 0>
  void compact(std::size_t i) {
    if constexpr (I < sizeof...(S)) {
      if (i != I) return compact<I + 1>(i);
      auto& v = std::get<I>(stores_);
      std::remove_reference_t<decltype(v)> kept;
      kept.reserve(v.size() - holes_[I]);
      for (std::uint32_t& e : entries_)
        if ((e >> slot_bits) == I) {
          kept.push_back(std::move(v[e & slot_mask]));
          e = static_cast<std::uint32_t>(I << slot_bits) | static_cast<std::uint32_t>(kept.size() - 1);
        }
      v = std::move(kept);
      holes_[I] = 0;
    }
  }

  std::tuple<std::vector<S>...> stores_;
  std::vector<std::uint32_t> entries_;  // per light: alternative << 27 | place in its array
  std::size_t holes_[sizeof...(S)] = {};
};

using light_list = basic_light_list<light>;
using light_ref = light_list::reference;

// A light of a list goes wherever a `light` does (light.hpp's functions,
// bounds_of, exact_importance), through this dispatch.
template <>
inline constexpr bool is_light_handle<light_ref> = true;
template <class F>
decltype(auto) dispatch(light_ref l, F&& f) { return l.visit(static_cast<F&&>(f)); }

// use_cheapest and use_cheapest_where_choice_does_not_pay (light.hpp) for
// light k of a list: the light is changed through set(), without a copy of
// the `auto` sampler.
inline bool use_cheapest(light_list& ls, std::size_t k) {
  std::optional<light> cheapest = cheapest_sampler(ls[k]);
  if (!cheapest) return false;
  ls.set(k, std::move(*cheapest));
  return true;
}
inline bool use_cheapest_where_choice_does_not_pay(light_list& ls, std::size_t k, std::span<const auto_receiver> rs,
                                                   std::span<const auto_choice> models = {}) {
  return !choice_pays(ls[k], rs, models) && use_cheapest(ls, k);
}

}  // namespace mcrt
