//! The steady laminar flow of the case: the fluid, the inlet velocity from the particle
//! Reynolds number, Ergun's pressure drop, and the files simpleFoam reads besides the mesh
//! (transport and turbulence properties, the initial fields, schemes and solution controls).

use pellet_geom::math::Real;

use super::header;

/// The fluid of the flow set-up: constant density and viscosity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fluid {
    /// What it is, for the files and the summary.
    pub name: &'static str,
    /// Kinematic viscosity ν (m²/s).
    pub nu: Real,
    /// Density ρ (kg/m³); simpleFoam solves for p / ρ, so it only converts the pressure to Pa.
    pub rho: Real,
}

/// Liquid water at 20 °C and 1 atm: μ = 1.0016 mPa s, ρ = 998.2 kg/m³ (IAPWS), ν = μ / ρ.
pub const WATER_20C: Fluid = Fluid { name: "water at 20 °C", nu: 1.0034e-6, rho: 998.2 };

/// The largest particle Reynolds number the laminar set-up accepts. Flow through packed
/// spheres is steady up to Re_p of about 100 and becomes unsteady between about 110 and 300
/// (the range the literature reports); above 300 a steady laminar solution is not the flow.
pub const MAX_REYNOLDS: Real = 300.0;

/// A steady incompressible laminar flow along +z through the bed, for simpleFoam.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Flow {
    /// The fluid.
    pub fluid: Fluid,
    /// Particle Reynolds number Re_p = ρ u_s dp / μ = u_s dp / ν.
    pub reynolds: Real,
    /// The pellets' volume-equivalent diameter dp (m).
    pub dp: Real,
    /// The packed section (m), from the floor to one pellet size below the bed's top: the
    /// pressure is averaged on these two planes.
    pub packed: (Real, Real),
}

impl Flow {
    /// The superficial velocity u_s = Re_p ν / dp (m/s), the uniform inlet velocity.
    pub fn velocity(&self) -> Real {
        self.reynolds * self.fluid.nu / self.dp
    }

    /// Ergun's pressure drop per unit length (Pa/m) at porosity `eps`:
    /// 150 μ u_s (1 − ε)² / (ε³ dp²) + 1.75 ρ u_s² (1 − ε) / (ε³ dp).
    pub fn ergun(&self, eps: Real) -> Real {
        let (u, mu, rho, dp) = (self.velocity(), self.fluid.nu * self.fluid.rho, self.fluid.rho, self.dp);
        150.0 * mu * u * (1.0 - eps).powi(2) / (eps.powi(3) * dp * dp)
            + 1.75 * rho * u * u * (1.0 - eps) / (eps.powi(3) * dp)
    }
}

/// `constant/transportProperties`: a Newtonian fluid of viscosity ν.
pub fn transport_properties(flow: &Flow) -> String {
    header("dictionary", "transportProperties")
        + &format!(
            "// {}: nu = {:e} m2/s (rho = {} kg/m3, not read by simpleFoam: p is p / rho).\n\
             transportModel  Newtonian;\n\nnu              [0 2 -1 0 0 0 0] {:e};\n",
            flow.fluid.name, flow.fluid.nu, flow.fluid.rho, flow.fluid.nu
        )
}

/// `constant/turbulenceProperties`: laminar.
pub fn turbulence_properties() -> String {
    header("dictionary", "turbulenceProperties") + "simulationType  laminar;\n"
}

/// `0/U` (m/s): u_s along +z at the inlet, zero gradient at the outlet, no slip on the tube
/// wall and the pellets.
pub fn field_u(flow: &Flow) -> String {
    header("volVectorField", "U")
        + &format!(
            "// Superficial velocity u_s = Re_p nu / dp = {} x {:e} / {:e} = {:e} m/s along +z.\n\
             dimensions      [0 1 -1 0 0 0 0];\n\ninternalField   uniform (0 0 0);\n\n\
             boundaryField\n{{\n    inlet\n    {{\n        type            fixedValue;\n        value           uniform (0 0 {:.9e});\n    }}\n\
             \x20   outlet\n    {{\n        type            zeroGradient;\n    }}\n\
             \x20   wall\n    {{\n        type            noSlip;\n    }}\n\
             \x20   pellets\n    {{\n        type            noSlip;\n    }}\n}}\n",
            flow.reynolds,
            flow.fluid.nu,
            flow.dp,
            flow.velocity(),
            flow.velocity()
        )
}

/// `0/p`, kinematic pressure p / ρ (m²/s²): 0 at the outlet, zero gradient elsewhere.
pub fn field_p() -> String {
    header("volScalarField", "p")
        + "// Kinematic pressure p / rho (m2/s2), 0 at the outlet.\n\
           dimensions      [0 2 -2 0 0 0 0];\n\ninternalField   uniform 0;\n\n\
           boundaryField\n{\n    inlet\n    {\n        type            zeroGradient;\n    }\n\
           \x20   outlet\n    {\n        type            fixedValue;\n        value           uniform 0;\n    }\n\
           \x20   wall\n    {\n        type            zeroGradient;\n    }\n\
           \x20   pellets\n    {\n        type            zeroGradient;\n    }\n}\n"
}

/// `system/fvSchemes`: steady, second order (bounded linear upwind for convection, limited
/// gradients and non-orthogonal corrections for snappyHexMesh's cells).
pub fn fv_schemes() -> String {
    header("dictionary", "fvSchemes")
        + "ddtSchemes\n{\n    default         steadyState;\n}\n\n\
           gradSchemes\n{\n    default         Gauss linear;\n    grad(U)         cellLimited Gauss linear 1;\n}\n\n\
           divSchemes\n{\n    default         none;\n    div(phi,U)      bounded Gauss linearUpwind grad(U);\n\
           \x20   div((nuEff*dev2(T(grad(U))))) Gauss linear;\n}\n\n\
           laplacianSchemes\n{\n    default         Gauss linear limited corrected 0.5;\n}\n\n\
           interpolationSchemes\n{\n    default         linear;\n}\n\n\
           snGradSchemes\n{\n    default         limited corrected 0.5;\n}\n"
}

/// `system/fvSolution`: SIMPLEC (`consistent yes`) with GAMG for p, stopping when the initial
/// residuals fall below 1e-4 (p) and 1e-5 (U); U under-relaxed by 0.9, p not (SIMPLEC needs none).
pub fn fv_solution() -> String {
    header("dictionary", "fvSolution")
        + "solvers\n{\n    p\n    {\n        solver          GAMG;\n        smoother        GaussSeidel;\n\
           \x20       tolerance       1e-8;\n        relTol          0.05;\n    }\n\n\
           \x20   U\n    {\n        solver          smoothSolver;\n        smoother        symGaussSeidel;\n\
           \x20       tolerance       1e-9;\n        relTol          0.1;\n    }\n}\n\n\
           SIMPLE\n{\n    nNonOrthogonalCorrectors 0;\n    consistent      yes;\n\n\
           \x20   residualControl\n    {\n        p               1e-4;\n        U               1e-5;\n    }\n}\n\n\
           relaxationFactors\n{\n    equations\n    {\n        U               0.9;\n    }\n}\n"
}
