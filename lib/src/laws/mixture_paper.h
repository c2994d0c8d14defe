/* mixture_paper.h - the paper's granular law (Manenti et al. 2018; docs/model.md sections 5-6):
 * a mixture at the packing limit whose apparent viscosity comes from its effective stress and
 * friction angle (rheology.h), held fixed above the threshold viscosity mu_thr and capped by the
 * limiting viscosity mu0; its module (mixture_paper.c) holds its case keys, its state (the pore
 * pressure's and the fixed bed's columns) and its per-step regime decision. The held-grain rule
 * is this law's and is stated here once, for the schemes that integrate its grains. */
#ifndef MIXSPH_MIXTURE_PAPER_H
#define MIXSPH_MIXTURE_PAPER_H

#include "law.h"

/** Whether a grain held fixed takes the kicks of its forces (it is only not drifted): not in a
 *  hold_fixed medium (SPHERA's rule: no acceleration, velocity exactly 0), nor when the implicit
 *  scheme prescribes held grains at rest (`rigid`, numerics.held_grains = "rigid"). */
static inline int mixture_paper_held_grain_kicked(const struct medium *m, int rigid)
{
    return !rigid && !m->paper.hold_fixed;
}

/** The viscosity [Pa s] a held grain enters the explicit viscous bound of the time step (4) with:
 *  min(mu0, mu_thr), the largest it can have once mobile, not its mu_thr (the paper's saving,
 *  dt ~ 1/mu0; docs/model.md section 6). Mobile grains have mu <= min(mu0, mu_thr). */
static inline double mixture_paper_held_viscosity(const struct medium *m)
{
    return m->paper.mu0 < m->paper.mu_thr ? m->paper.mu0 : m->paper.mu_thr;
}

#endif
