/* drucker_prager_params.h - the parameters of the elastic-perfectly-plastic granular law's
 * Drucker-Prager cone (drucker_prager.h, elastic_plastic.c; docs/model.md section 10): read from
 * media.<name> by its key table, the matched cone derived by its finish. A definition only. */
#ifndef MIXSPH_DRUCKER_PRAGER_PARAMS_H
#define MIXSPH_DRUCKER_PRAGER_PARAMS_H

struct drucker_prager_params {
    double cohesion;                  /* c [Pa] */
    double dilatancy_deg;             /* psi [deg] */
    double alpha_phi, k_c, alpha_psi; /* the plane-strain matched cone (drucker_prager.h) */
};

#endif
