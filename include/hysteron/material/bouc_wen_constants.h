#ifndef hysteron_material_bouc_wen_constants_h
#define hysteron_material_bouc_wen_constants_h

namespace hysteron
{
  namespace Material
  {
    /// The triaxial Bouc-Wen law's point kernels (source/material/bouc_wen_kernels.h,
    /// not installed) read these constants, which BoucWen<dim> holds.
    namespace BoucWenKernels
    {
      /// Everything a kernel needs, precomputed once per material.
      struct Constants
      {
        double       E = 1, nu = 0;
        double       two_mu = 1, lambda_eff = 0; ///< D = lambda_eff 1 (x) 1 + 2 mu I
        double       sigma_y0 = 1, eps_y = 1;
        double       H     = 0; ///< H' = a E / (1 - a)
        double       kin   = 0; ///< (1 - m) C_p: alpha = kin eps_p
        double       kin_q = 0; ///< 3/2 kin = (1 - m) H'
        double       iso   = 0; ///< m H': sigma_y = sigma_y0 + iso eps_ps
        double       n = 8, beta = 0.5, gamma = 0.5;
        unsigned int n_integer = 8; ///< n if n is an integer in [1, 1024], else 0
        double       c_eta = 0, m_u = 1, inv_m_u1 = 0.5; ///< 1 / (m_u + 1)
        double       c_nu_scaled  = 0;                   ///< c_nu / (sigma_y0 eps_y)
        double       tol          = 1e-6;
        double       inv_tol      = 1e6; ///< 1 / tol
        double       inv_sigma_y0 = 1, inv_eps_y = 1, inv_energy = 1;
        unsigned int max_substeps   = 100000;
        unsigned int max_iterations = 50;
        unsigned int n_half         = 0; ///< n / 2 if n is an even integer in [2, 1024], else 0
        double       radial_g       = 0; ///< 9/4 / (H' + 3 mu) (stage_rates(), 3D/plane strain)
        double       H_3mu          = 0; ///< H' + 3 mu
      };
    } // namespace BoucWenKernels
  } // namespace Material
} // namespace hysteron

#endif
