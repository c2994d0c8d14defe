/* mixture_paper_params.h - the parameters of the paper's granular law (mixture_paper.h; docs/model.md
 * sections 5-6), read from media.<name> by its key table and derived by its finish. A definition
 * only (struct medium holds one; mixture_paper.h holds the law). */
#ifndef MIXSPH_MIXTURE_PAPER_PARAMS_H
#define MIXSPH_MIXTURE_PAPER_PARAMS_H

struct mixture_paper_params {
    double eps_f_mu_f; /* eps_f mu_f [Pa s] (0 if dry) */
    double mu_thr;     /* threshold viscosity [Pa s] */
    double mu0;        /* limiting viscosity [Pa s]; INFINITY: no limit */
    int mu1_mode;      /* the "mu1" rheology of Run 7: mu_thr = mu1, no limit */
    int hold_fixed;    /* a fixed grain gets no acceleration (SPHERA's implementation) */
};

#endif
