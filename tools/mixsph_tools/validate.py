"""mixsph-validate CASE [OPTIONS]: run a validation campaign of mixsph against its paper.

    mixsph-validate vajont --runs 1,2,4 --dx 0.01     # tools/vajont_validate.py, docs/validation/vajont.md
    mixsph-validate erosive --runs 2,6 --jobs 2       # tools/erosive_dambreak.py, docs/validation/erosive_dambreak.md
    mixsph-validate erosive-ensemble --group explicit DIR... --group implicit DIR...   # tools/erosive_ensemble.py
    mixsph-validate column --runs 1,2,3 --jobs 2      # tools/column_collapse.py, docs/validation/granular.md
    mixsph-validate convergence --set numerics.viscosity=1   # tools/vajont_convergence.py, docs/validation/vajont.md
    mixsph-validate runout --aspects 0.5,1,2                 # tools/column_runout.py, docs/validation/granular.md
    mixsph-validate heap --refine                            # tools/granular_heap.py, docs/validation/granular.md
    mixsph-validate impulse --refine                         # tools/impulse_waves.py, docs/validation/granular.md
    mixsph-validate step --case cases/column_collapse.json   # tools/step_independence.py, docs/validation/granular.md

CASE's options, outputs and exit status are its script's (``mixsph-validate CASE --help``).
"""

import importlib
import sys

CASES = {
    "vajont": ("vajont_validate", "the Vajont runs V1-V6 of Manenti et al. (2018), Tables 4-5"),
    "erosive": ("erosive_dambreak", "the erosive dam break Runs 1-7 of Manenti et al. (2018), Tables 1-2"),
    "erosive-ensemble": ("erosive_ensemble", "ensembles of erosive dam break runs: a scheme's difference "
                         "against its runs' drift under a round-off-size perturbation"),
    "column": ("column_collapse", "a dry granular column collapse: does the deposit come to rest?"),
    "runout": ("column_runout", "dry columns of several aspect ratios against the run-out and final-height "
               "laws of Lube et al. (2005); do their deposits rest?"),
    "heap": ("granular_heap", "a heap 3 degrees below phi stays; a 45-degree heap fails and rests near phi"),
    "impulse": ("impulse_waves", "impulse waves of granular slides against a_M / h = (4/9) P^0.8 of Heller & "
                "Hager (2010)"),
    "step": ("step_independence", "a case at its default time step, half and a quarter of it, against the "
             "spread of gravity-perturbed twins"),
    "convergence": ("vajont_convergence", "Vajont V1 against the particle spacing, and the cheapest spacing "
                    "within a tolerance of the finest"),
}


def usage():
    return "usage: mixsph-validate CASE [OPTIONS]   (mixsph-validate CASE --help)\n\ncases:\n" + "".join(
        f"  {name:16s}  {what}\n" for name, (_, what) in CASES.items())


def main(argv=None):
    argv = sys.argv[1:] if argv is None else list(argv)
    if not argv or argv[0] in ("-h", "--help"):
        print(usage(), end="", file=sys.stdout if argv else sys.stderr)
        return 0 if argv else 2
    if argv[0] not in CASES:
        print(f"mixsph-validate: error: unknown case '{argv[0]}'\n\n{usage()}", end="", file=sys.stderr)
        return 2
    module = importlib.import_module(CASES[argv[0]][0])
    module.main(argv[1:], prog=f"mixsph-validate {argv[0]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
