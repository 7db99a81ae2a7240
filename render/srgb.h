// The sRGB transfer function on the CPU, as the renderer's shaders apply it (surface_renderer.cpp's
// srgb_encode, IEC 61966-2-1): for colours computed outside a draw that must match the images' encoding.
#pragma once

#include <array>
#include <cstdint>

namespace waxwork {

// Linear [0, 1] -> encoded [0, 1]: 12.92 c below 0.0031308, else 1.055 c^(1/2.4) - 0.055.
double srgb_encode(double linear);

// Encoded [0, 1] -> linear [0, 1], the inverse of srgb_encode: c / 12.92 up to 0.04045, else
// ((c + 0.055) / 1.055)^2.4.
double srgb_decode(double encoded);

// A linear value to its 8-bit sRGB code: clamped to [0, 1] (as the shaders clamp before encoding),
// encoded, then rounded to the nearest of 0..255 as OpenGL converts a float to an 8-bit normalised
// colour. NaN gives 0.
uint8_t srgb_byte(double linear);
std::array<uint8_t, 3> srgb_bytes(const std::array<double, 3>& linear);

// What every view draws behind the model (8-bit sRGB): the renderer's clear colour and the CPU
// images' background, so that pictures put side by side match.
inline constexpr std::array<uint8_t, 3> kViewBackground{38, 40, 46};

}  // namespace waxwork
