#pragma once
// The lecture's table of measured friction coefficients (its section on forces, in Korean
// "마찰계수 - 경험치", empirical values): material pairs, static and kinetic, dry ("마른 상태") and
// lubricated ("미끈거리는 상태", slippery). Rows are in the lecture's order, numbers exactly as
// printed ("0.30" and "1.0" are the doubles 0.3 and 1.0); a cell the lecture leaves empty is
// std::nullopt, never 0. tests/test_exact_motion.cpp re-reads the seed's table, when the seed
// is present, and checks every cell and every translated name against it.
//
// Naming rule: a pair is named "<upper>_on_<lower>" (the upper body slides on the lower
// surface), each material a lowercase English identifier: words joined by '_', the lecture's
// parenthetical qualifier appended ("나무(결을 따라)", wood (along the grain) ->
// "wood_along_grain"). A Korean word is always translated to the same identifier.
//
// Entries that look physically odd (kept as printed; the tests list the first three
// programmatically, so this note stays complete):
// - aluminum_on_aluminum: kinetic 1.4 > static 1.1 (dry). The lecture itself says kinetic is
//   usually below static. sliding_block.hpp handles mu_k > mu_s consistently (see there).
// - steel_on_lead: kinetic = static = 0.95 (dry): no breakaway.
// - ski_on_snow: lubricated (wet snow) kinetic 0.1 is above the dry kinetic 0.05, and
//   lubricated static 0.14 equals dry static: here "lubricated" raises the friction (real for
//   wet snow, which drags on a ski, but the opposite of every other row).
// - cast_iron_on_cast_iron: static 1.1 vs kinetic 0.15 (dry), a ratio of 7.3 where the other
//   pairs with both values lie between 1.0 and 3.5 (ice_on_ice 3.3, human_joint 3.3).
// - diamond_on_diamond: lubricated static 0.1 = dry static 0.1 (lubrication has no effect).
// - Three wood-on-wood rows with different numbers: wood_on_wood_along_grain (0.62 / 0.48),
//   wood_on_wood_across_grain (0.54 / 0.32), and plain wood_on_wood (0.42 / 0.30).
// - Rows with a kinetic value but no static one (cast_iron_on_wood dry and lubricated,
//   copper_on_steel and wood_on_wood_across_grain lubricated): a simulation needing mu_s there
//   has no number from the lecture and must say so rather than substitute.
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace stepbench::exact {

struct friction_record {
  std::string_view upper;  // material of the sliding body
  std::string_view lower;  // material of the surface
  std::optional<double> mu_s_dry;
  std::optional<double> mu_k_dry;
  std::optional<double> mu_s_lubricated;
  std::optional<double> mu_k_lubricated;
};

// {} is an empty cell of the lecture's table.
inline constexpr std::array<friction_record, 33> friction_table{{
    {"aluminum", "aluminum", 1.1, 1.4, 0.3, {}},                  // 알루미늄 / 알루미늄
    {"aluminum", "steel", 0.61, 0.47, {}, {}},                    // 알루미늄 / 강철
    {"car_brake_pad", "cast_iron_brake_disc", 0.4, {}, 0.2, {}},  // 차 브레이크 패드 / 주철 브레이크 디스크
    {"brass", "steel", 0.35, 0.3, 0.19, {}},                      // 놋쇠 / 강철
    {"brick", "wood", 0.6, {}, {}, {}},                           // 벽돌 / 나무
    {"cast_iron", "cast_iron", 1.1, 0.15, 0.2, 0.07},             // 주철 / 주철
    {"cast_iron", "wood", {}, 0.49, {}, 0.075},                   // 주철 / 나무
    {"copper", "cast_iron", 1.05, 0.29, {}, {}},                  // 구리 / 주철
    {"copper", "copper", 1.0, {}, 0.08, {}},                      // 구리 / 구리
    {"copper", "steel", 0.53, 0.36, {}, 0.18},                    // 구리 / 강철
    {"copper", "glass", 0.68, 0.53, {}, {}},                      // 구리 / 유리
    {"diamond", "diamond", 0.1, {}, 0.1, {}},                     // 다이아몬드 / 다이아몬드
    {"glass", "glass", 0.94, 0.4, 0.1, 0.09},                     // 유리 / 유리
    {"glass", "metal", 0.5, {}, 0.2, {}},                         // 유리 / 금속
    {"glass", "nickel", 0.78, 0.56, {}, {}},                      // 유리 / 니켈
    {"human_joint", "human_joint", 0.01, 0.003, {}, {}},          // 사람의 관절 / 사람의 관절
    {"ice", "ice", 0.1, 0.03, {}, {}},                            // 얼음 / 얼음
    {"leather", "metal", 0.6, {}, 0.2, {}},                       // 가죽 / 금속
    {"leather", "wood_along_grain", 0.61, 0.52, {}, {}},          // 가죽 / 나무(결을 따라)
    {"nylon", "nylon", 0.2, {}, {}, {}},                          // 나일론 / 나일론
    {"wood", "wood_along_grain", 0.62, 0.48, {}, {}},             // 나무 / 나무(결을 따라)
    {"wood", "wood_across_grain", 0.54, 0.32, {}, 0.072},         // 나무 / 나무(결을 가로질러)
    {"rubber", "asphalt", 0.85, 0.67, 0.53, {}},                  // 고무 / 아스팔트
    {"rubber", "concrete", 0.9, 0.68, 0.7, 0.58},                 // 고무 / 콘크리트
    {"rubber", "ice", 0.15, {}, {}, {}},                          // 고무 / 얼음
    {"silver", "silver", 1.4, {}, 0.55, {}},                      // 은 / 은
    {"steel", "cast_iron", 0.4, 0.23, 0.183, 0.133},              // 강철 / 주철
    {"steel", "ice", 0.1, 0.05, {}, {}},                          // 강철 / 얼음
    {"steel", "lead", 0.95, 0.95, 0.5, 0.3},                      // 강철 / 납
    {"steel", "steel", 0.74, 0.57, 0.15, 0.1},                    // 강철 / 강철
    {"ski", "snow", 0.14, 0.05, 0.14, 0.1},                       // 스키 / 눈
    {"wood", "wood", 0.42, 0.30, 0.2, {}},                        // 나무 / 나무
    {"wood", "concrete", 0.62, {}, {}, {}},                       // 나무 / 콘크리트
}};

// True when `name` is "<upper>_on_<lower>" for this record.
constexpr bool has_name(const friction_record& r, std::string_view name) {
  constexpr std::string_view on = "_on_";
  return name.size() == r.upper.size() + on.size() + r.lower.size() && name.starts_with(r.upper) &&
         name.substr(r.upper.size(), on.size()) == on && name.ends_with(r.lower);
}

// The record's name (allocates; for listings, not for inner loops).
inline std::string friction_name(const friction_record& r) {
  return std::string(r.upper) + "_on_" + std::string(r.lower);
}

namespace detail {
// A record's name in a fixed buffer, for the compile-time check below (constexpr std::string
// is not usable with every compiler and standard library pair this project meets).
struct friction_name_buffer {
  std::array<char, 64> chars{};
  std::size_t size = 0;
  constexpr void append(std::string_view s) {
    for (char c : s) chars[size++] = c;
  }
  constexpr std::string_view view() const { return {chars.data(), size}; }
};

// Every record's name finds that record and no other (checked at compile time).
constexpr bool friction_names_unique() {
  for (const auto& a : friction_table) {
    friction_name_buffer name;
    name.append(a.upper);
    name.append("_on_");
    name.append(a.lower);
    for (const auto& b : friction_table)
      if ((&a == &b) != has_name(b, name.view())) return false;
  }
  return true;
}
}  // namespace detail
static_assert(detail::friction_names_unique(), "two friction records answer to the same name");

}  // namespace stepbench::exact
