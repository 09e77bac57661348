#pragma once
// Light units of the engine.
//
// The engine shades in radiometric units (watts), linear RGB, metres:
//   - point and spot lights: radiant intensity, W/sr, per colour channel (Light::intensity x colour)
//   - directional lights: irradiance on a surface facing the light, W/m^2
//   - rectangular area lights: emitted radiance, W/(m^2 sr), one-sided (towards the light's -Z)
//   - emissive materials: emitted radiance, W/(m^2 sr)
// glTF's KHR_lights_punctual uses photometric units (candela for point/spot, lux for
// directional). They are converted with the luminous efficacy of 683 lm/W that glTF and
// the SI definition of the candela use, so 683 cd = 1 W/sr and 683 lx = 1 W/m^2. glTF
// emissive factors (times KHR_materials_emissive_strength) are taken as radiance directly.

namespace engine::units {

/// Luminous efficacy used to convert photometric glTF values to the engine's watts.
inline constexpr float kLumensPerWatt = 683.0f;

/// candela (lm/sr) -> W/sr
constexpr float candela_to_w_per_sr(float cd) { return cd / kLumensPerWatt; }
/// W/sr -> candela
constexpr float w_per_sr_to_candela(float w_sr) { return w_sr * kLumensPerWatt; }
/// lux (lm/m^2) -> W/m^2
constexpr float lux_to_w_per_m2(float lux) { return lux / kLumensPerWatt; }
/// W/m^2 -> lux
constexpr float w_per_m2_to_lux(float w_m2) { return w_m2 * kLumensPerWatt; }

}  // namespace engine::units
