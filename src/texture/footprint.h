// The footprint of a pixel in texture space, for the level of detail (SPEC §7, seed 001) and for
// anisotropic filtering (issue 5).
//
// Based on: SPEC §7 (seed 001: the pixel as a circle whose projection onto the textured plane is an
// ellipse, its major axis the filter diameter); Heckbert 1989, "Fundamentals of Texture Mapping and
// Image Warping" (the ellipse from the Jacobian of the screen-to-texture mapping).
//
// Symbols. Texture coordinates are rational in screen position (SPEC §2, §7): u = U/Q, v = V/Q with
// U, V, Q linear in the pixel position (x, y) — for a triangle with per-vertex UVs, U = Σλ_k u_k,
// V = Σλ_k v_k, Q = Σλ_k = 1/w (geometry/setup.cpp). Their gradients give the Jacobian
//     J = [∂u/∂x ∂u/∂y; ∂v/∂x ∂v/∂y],   ∂u/∂x = (U_x·Q − U·Q_x) / Q²  (and alike),
// in texels when u, v are scaled by the texture's size. A pixel of diameter 1 maps, to first order,
// onto the ellipse J·(unit-diameter circle), whose axes are J's singular values σ₁ ≥ σ₂. Every
// pixel is computed on its own from the planes — no neighbour differences (the seed requires it).
#pragma once

namespace sv::texture {

// A linear function of the pixel position: value at the pixel, and its x and y gradients.
struct LinearAt {
  double value, dx, dy;
};

struct Footprint {
  double major = 0, minor = 0;  // the ellipse's diameters, in texels (σ₁ ≥ σ₂ of J)
  double axisX = 1, axisY = 0;  // unit direction of the major axis, in texel space
  double lod = 0;               // log2(major), at least 0: the pyramid level whose texel ≈ major
};

// The footprint of the pixel where U, V, Q have the given values and gradients (Q > 0), for a
// texture of texelsU × texelsV texels (u, v in [0, 1] across it).
Footprint pixelFootprint(const LinearAt& U, const LinearAt& V, const LinearAt& Q, double texelsU,
                         double texelsV);

// The seed's estimate for a planar face (SPEC §7): the projected diameter
//     S ≈ 2·Δ·d / (N_x·Δ_x·X₀ + N_y·Δ_y·Y₀ + N_z)²,   Δ = max(Δ_x, Δ_y),
// in the plane's own length units, with (X₀, Y₀) the pixel's offset from the screen centre in
// pixels, Δ_x, Δ_y the sampling intervals (2/M)·tan(α/2), (2/N)·tan(β/2), and the plane N·P + d = 0
// in eye space (|N| = 1, the eye looking down −z — so the seed's denominator, written for a +z
// view, takes N_z as −N_z here). Exact at the screen centre for a plane facing the eye; ≈ 20 % off
// at the corners of a 40°×30° view, as the seed states.
double seedFootprint(double nx, double ny, double nz, double d, double deltaX, double deltaY,
                     double x0, double y0);

}  // namespace sv::texture
