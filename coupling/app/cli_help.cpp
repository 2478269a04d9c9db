// Help texts of the `frictherm` program.
#include "cli.hpp"

namespace frictherm::cli {

const char* const kProgramHelp =
    "frictherm - Material Point Method mechanics runs from JSON scenes, written to HDF5\n"
    "\n"
    "usage: frictherm COMMAND [ARGS]\n"
    "       frictherm --version | --help\n"
    "\n"
    "commands:\n"
    "  run SCENE [-o OUT.h5] [--threads N] [--quiet] [--set KEY=VALUE ...]\n"
    "                                                  run a scene, write an HDF5 file (+ XDMF)\n"
    "  resume RUN.h5 [-o OUT.h5]                       continue a run from RUN.h5.checkpoint, appending\n"
    "                                                  to RUN.h5\n"
    "  continue RUN.h5 [-o OUT.h5] [--set thermal.KEY=VALUE ...]\n"
    "                                                  rerun the thermal continuation from the\n"
    "                                                  end-of-loading checkpoint with other thermal settings\n"
    "  validate SCENE [--set KEY=VALUE ...]            check a scene and print a summary\n"
    "  export-csv RUN.h5 [-o OUT.csv]                  print the time series of a run as CSV\n"
    "  microstructure SCENE [-o IMAGE.pgm]             write the grain image of an ellipse_packing body\n"
    "  ensemble SCENE --seed-key KEY [-n N] [-o OUT.h5] run a scene over N seeds (MPI when under\n"
    "                                                  mpirun), aggregate the hot spots\n"
    "  help [COMMAND]                                  show help for a command\n"
    "\n"
    "Every command takes --help. Exit codes: 0 ok, 1 simulation failed, 2 usage or scene error.\n"
    "Scene reference: docs/scenes.md\n";

const char* const kRunHelp =
    "usage: frictherm run SCENE [-o OUT.h5] [--force] [--threads N] [--quiet] [--set KEY=VALUE ...]\n"
    "\n"
    "Validates SCENE, then runs it to run.end_time, writing particle snapshots, the time series and\n"
    "run metadata to one HDF5 file (and an XDMF file beside it for ParaView).\n"
    "\n"
    "options:\n"
    "  -o, --output OUT.h5   output file (default: the scene's output.file, else SCENE_NAME.h5)\n"
    "  -f, --force           replace OUT.h5 if it exists (as output.overwrite: true does); without it\n"
    "                        an existing OUT.h5 is refused (exit code 2). The scene and its images\n"
    "                        are never written over.\n"
    "  -t, --threads N       OpenMP threads (default: the scene's run.threads, else all cores)\n"
    "  -q, --quiet           no progress line and no summary\n"
    "  --checkpoint-every S  also write OUT.h5.checkpoint every S wall-clock seconds (besides the\n"
    "                        scene's run.checkpoint_interval in simulated time; docs/checkpoints.md)\n"
    "  -s, --set KEY=VALUE   change one scene value before validation (repeatable), e.g.\n"
    "                        --set solver.cfl=0.3 --set 'bodies[0].velocity=[2, 0]'; VALUE is JSON\n"
    "                        (a bare word is a string). Handy for sweeps: a loop over values.\n"
    "  -h, --help            this help\n"
    "\n"
    "A progress line (step, simulated time, steps/s, ETA) is shown when stderr is a terminal.\n"
    "If the simulation breaks down (non-finite values, a particle leaving the grid) the run stops,\n"
    "the failing state is written to /failure, every earlier snapshot stays readable, and the exit\n"
    "code is 1. SIGINT (Ctrl-C) or SIGTERM ends the run after the current step: the series and a last\n"
    "snapshot are written, /meta/status is `interrupted`, and the exit code is 128 + the signal\n"
    "(130 for SIGINT, 143 for SIGTERM); a second signal ends the program at once. Series rows reach\n"
    "the file at least every 2 s of wall time.\n"
    "While it runs the output is OUT.h5.<pid>.part (readable at any time); it is renamed to OUT.h5 when\n"
    "the run ends (completed, failed or interrupted), so a second run writing OUT.h5 cannot destroy it.\n"
    "\n"
    "One process runs the whole scene (threads: --threads). `mpirun -n K frictherm run` is refused: the\n"
    "domain-decomposed engine (docs/distributed.md) is a library for now, for 2D and 3D linear-elastic\n"
    "multimaterial contact with frictional work; penalty contact stays serial and is refused there.\n";

const char* const kValidateHelp =
    "usage: frictherm validate SCENE [--set KEY=VALUE ...]\n"
    "\n"
    "Checks SCENE without running it: every key, type and range, names of materials and bodies,\n"
    "image files, bodies inside the grid. Builds the particles and prints a summary (dimension,\n"
    "grid, materials, bodies with particle counts, time step and estimated step count), then \"ok\".\n"
    "Exit code 0 when the scene is valid, 2 with one message naming the key path otherwise.\n"
    "--set KEY=VALUE changes a value first, as for `frictherm run`.\n";

const char* const kExportCsvHelp =
    "usage: frictherm export-csv RUN.h5 [-o OUT.csv] [--force]\n"
    "\n"
    "Writes the time series (/series) of a run as CSV: a header line of column names, then one\n"
    "line per row. Works on runs that failed part-way too.\n"
    "\n"
    "options:\n"
    "  -o, --output OUT.csv  output file (default: standard output)\n"
    "  -f, --force           replace OUT.csv if it exists (else refused); never RUN.h5 itself\n"
    "  -h, --help            this help\n";

}  // namespace frictherm::cli
