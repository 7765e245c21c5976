// Constants of the L1 spherical-harmonic light propagation volume, shared verbatim by
// the C++ backend and the GLSL shaders (plain #defines: valid C++ and GLSL).
//
// SH convention: coefficient order (Y00, Y1x, Y1y, Y1z); a direction w evaluates
// as  c0*Y00 + Y1*(c1x*w.x + c1y*w.y + c1z*w.z).
#ifndef SSLPV_LPV_CONSTANTS_H
#define SSLPV_LPV_CONSTANTS_H

#define SSLPV_SH_Y00 0.28209479177387814
#define SSLPV_SH_Y1 0.4886025119029199

// Clamped cosine lobe max(0, n.w) projected to L1: (sqrt(pi)/2, sqrt(pi/3) n).
#define SSLPV_COSINE_LOBE_C0 0.8862269254527579
#define SSLPV_COSINE_LOBE_C1 1.0233267079464885

// Integrals over the hemisphere around n: of Y00 is sqrt(pi), of Y1m is
// (sqrt(3 pi)/2) n_m. Used to turn a cell's intensity into radiance at a surface.
#define SSLPV_HEMI_Y00 1.7724538509055159
#define SSLPV_HEMI_Y1 1.5349900619197328

// Solid angles of a destination cell's faces seen from the source cell centre
// (Kaplanyan-Dachsbacher): the face opposite the source, and each of the four side
// faces. 4*side + front = 2*pi/3 exactly. (0.4234413544, seen in many LPV shaders,
// is a typo.)
#define SSLPV_FRONT_FACE_SOLID_ANGLE 0.4006696846462392
#define SSLPV_SIDE_FACE_SOLID_ANGLE 0.4234313544367392

// Total flux of a cell whose DC coefficient is c0: integral of c0*Y00 over the sphere.
#define SSLPV_FLUX_PER_C0 3.5449077018110318

#define SSLPV_PI 3.14159265358979323846

// Of an isotropic cell's c0, the share each of its six neighbours receives per step (in
// their c0): its power split six ways, re-emitted as a cosine lobe,
// C0 / pi * FLUX_PER_C0 / 6 = 1/6. Used where a scheme's steps keep every cell isotropic
// (volume/cpu/propagate.cpp, shaders/lpv_transfer.glsl).
#define SSLPV_ISOTROPIC_NEIGHBOUR_SHARE (SSLPV_COSINE_LOBE_C0 / SSLPV_PI * SSLPV_FLUX_PER_C0 / 6.0)

// --steps auto: a channel whose step holds less than this fraction of its accumulated
// power has converged as far as float sums can tell. Its decay ratio is then rounding
// noise (on lavapipe, denormals that stall at a ratio of 1), so it neither holds up the
// stop nor adds a tail; a tail r/(1-r) times this is negligible unless r > 0.9999.
#define SSLPV_AUTO_STEP_NEGLIGIBLE 1e-6

// --steps auto as a Chebyshev semi-iteration (PropagationOptions::chebyshev): plain steps
// that estimate the step operator's spectral radius from their power ratio before the
// iterates start, and the iterates over which the observed shrink of their change is
// averaged (a running mean of its log with this weight on the newest) before the stop
// may use it.
#define SSLPV_CHEBYSHEV_PROBE_STEPS 16
#define SSLPV_CHEBYSHEV_RATE_WINDOW 8
// The semi-iteration's floor: where a channel's change has not halved within this many
// iterates and its total has moved by less than the tolerance over them, the iterates
// differ by float rounding only (a sphere of albedo-1 medium at 100 mean free paths a
// cell stalled at a change of 7e-5 of its total and ran into the step cap).
#define SSLPV_CHEBYSHEV_STALL_WINDOW 64
// Spectral radius estimates stay below 1 by this much (a ratio of 1 is float noise).
#define SSLPV_CHEBYSHEV_MAX_RHO (1.0 - 1e-7)
// A warm-started semi-iteration (PropagationWarmStart) stops only once the light still to
// come in every cell the shading reads is under a tolerance of the cell's own light
// (PropagationOptions::warmLocalTolerance); cells darker than this share of the mean
// cell's light are held to it instead, so that float noise in the dark does not keep a
// run going.
#define SSLPV_WARM_START_LOCAL_FLOOR 1e-2

// The calibrated exit law's table (volume/calibration/exit_law.h): rows over t = sqrt(1 - a') at
// t = k / ALBEDO_INTERVALS, columns over the outside cosine mu_o = j / MU_INTERVALS,
// row-major, (ALBEDO_INTERVALS + 1) x (MU_INTERVALS + 1) floats, bilinear.
#define SSLPV_EXIT_LAW_ALBEDO_INTERVALS 32
#define SSLPV_EXIT_LAW_MU_INTERVALS 64

// The calibrated injection's oblique-entry gain (volume/calibration/lpv_calibration.h): per cell and
// channel, its values at y = 1 - k / OBLIQUE_INTERVALS, k = 1 .. OBLIQUE_INTERVALS, where
// y = cos^2 of the outside incidence angle (1 at normal incidence, where the gain is 1),
// piecewise linear in y.
#define SSLPV_OBLIQUE_INTERVALS 4

// The calibrated shading's single-scattering term (volume/cpu/single_scattering.h) looks for
// where the view ray leaves the object this many optical depths deep (e^-6: 0.25 % of the
// light is beyond), in steps of one cell.
#define SSLPV_SINGLE_SCATTERING_EXIT_DEPTH 6.0

#endif
