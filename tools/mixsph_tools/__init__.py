"""mixsph_tools: the Python side of mixsph's tools/ folder.

    import mixsph_tools as mt
    mon = mt.read_monitors("out/x/monitors.csv")        # {"t": array, "water_front": array, ...}
    summ = mt.read_summary("out/x/summary.json")        # dict; JSON null -> nan in "outputs"

Modules, one concept each:

- ``readers``: the files a ``mixsph run`` writes (monitors.csv, summary.json, profiles,
  snapshots, checkpoints), every reader raising ``ToolError`` with a message naming the file;
- ``report``: numbers and paths as the scripts print them, aligned and Markdown tables, CSV files;
- ``runs``: a run folder's stamp (the settings it was made with), the --reuse decision, starting
  ``mixsph run`` in it;
- ``campaign``: the campaign runner of the validation scripts (their shared options, the runs
  made at most --jobs at once, the fields of every run's result);
- ``validate``: the ``mixsph-validate vajont|erosive ...`` command.

The names of ``readers``, ``report`` and ``runs`` are also this package's own (``mt.show``).
"""

from .readers import *  # noqa: F401,F403
from .report import *  # noqa: F401,F403
from .runs import *  # noqa: F401,F403
