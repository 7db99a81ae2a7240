// Optical properties of a scattering material and the diffusion-approximation quantities derived from
// them (Li et al. 2013 Sec. 3.1, Eqs. 1-3; Jensen et al. 2001).
//
// All coefficients are per millimetre. A material is waxwork::TetMaterial (tetops/tet_mesh.h): per rgb
// channel mu_a and mu_s', plus the relative index of refraction eta = n_object / n_outside.
//
// mu_a = 0 (spectralon) is valid: the interior operator div(kappa grad) is then singular on its own, but
// the Robin boundary term of Eq. 2 adds a positive diagonal on every boundary vertex, so the assembled
// matrix stays symmetric positive definite for every connected piece that has a boundary (every piece
// of a finite volume does).
#pragma once

#include "tetops/model_scale.h"
#include "tetops/tet_mesh.h"

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace waxwork {

// Diffusion coefficient kappa = 1 / (3 (mu_a + mu_s')), in mm (Eq. 1).
double diffusion_coefficient(double mua, double musp);

// Effective transport coefficient sigma_tr = sqrt(3 mu_a (mu_a + mu_s')) = sqrt(mu_a / kappa), per mm.
double effective_transport_coefficient(double mua, double musp);

// Diffusion length 1 / sigma_tr in mm: the distance over which the fluence falls by 1/e in an infinite
// medium; the mesh must resolve it near lit surfaces. Infinite when mu_a = 0.
double diffusion_length(double mua, double musp);

// Diffuse Fresnel reflectance, the Egan & Hilgeman fit used by Jensen et al. 2001:
// F_dr = -1.440/eta^2 + 0.710/eta + 0.668 + 0.0636 eta. Valid for eta in [1, 3] (see validate_material).
double diffuse_fresnel_reflectance(double eta);

// A = (1 + F_dr) / (1 - F_dr), the internal-reflection parameter of the Robin boundary (Eq. 2).
double boundary_reflection_parameter(double eta);

// Total diffuse reflectance R_d of a semi-infinite slab per rgb channel, in [0, 1): the dipole
// profile R_d(r) of Jensen et al. 2001 integrated over the surface plane, which has the closed form
// R_d = (alpha'/2) (1 + exp(-(4/3) A sqrt(3 (1 - alpha')))) exp(-sqrt(3 (1 - alpha'))) with the reduced
// albedo alpha' = mu_s' / (mu_a + mu_s') and A = boundary_reflection_parameter(eta). Independent of
// scale: the colour a thick slab of the material shows under white light, 1 without absorption.
std::array<double, 3> diffuse_reflectance(const TetMaterial& material);

// Unpolarised Fresnel transmittance 1 - (R_s + R_p)/2 for light arriving at angle acos(cos_incident)
// from the side of index 1 onto a side of relative index eta. eta < 1 means leaving a denser medium:
// total internal reflection gives 0. cos_incident is clamped to [0, 1].
double fresnel_transmittance(double cos_incident, double eta);

// Throws InvalidArgumentError (message starts with `context`) for a NaN or infinite coefficient,
// mu_a < 0, mu_s' <= 0, eta outside [1, 3] (the F_dr fit is meaningless there) or coefficients above
// 1e4 per mm (a mean free path under 0.1 micrometre: a unit error, not a material).
void validate_material(const TetMaterial& material, std::string_view context = "material");

// The coefficients are per millimetre, so every scene has a scale in millimetres per model unit
// (tetops/model_scale.h). Throws InvalidArgumentError "WHAT must be a length in mm per model unit between 1e-6 and 1e6 (got X)"
// for a scale outside that range or not finite.
void validate_mm_per_unit(double mm_per_unit, std::string_view what = "scale");

// Measured materials of Jensen et al. 2001 (Fig. 5 table), compiled in.
std::vector<std::string> material_preset_names();
// Throws InvalidArgumentError naming the known presets when `name` is not one of them.
TetMaterial material_preset(std::string_view name);
// A preset's name when `material` equals one, else "custom".
std::string material_label(const TetMaterial& material);

// One material per tet: `override` everywhere when given, else the volume's stored materials, else
// the marble preset. Every material is validated (validate_material); a stored one that fails names
// its tet.
std::vector<TetMaterial> resolve_materials(const TetMesh& mesh, const std::optional<TetMaterial>& override);
// What resolve_materials(mesh, override) fills the tets with, by name: the override's preset name
// ("custom" for other coefficients; material_label), "stored" for the volume's own, else "marble".
std::string resolved_materials_name(const TetMesh& mesh, const std::optional<TetMaterial>& override);

}  // namespace waxwork
