#!/usr/bin/env python3
"""Every ctest labelled `mpi` runs with OMPI_MCA_mpi_yield_when_idle=1 (issue 34, item 7).

Open MPI 4.1 polls busily while a rank waits unless it counts more ranks than slots; on a loaded
2-core machine the waiting ranks then take the cores from the ones that work, and CliMpirun.Checkpoints
went from 85 s alone to a 300 s timeout. Reads the test list of BUILD_DIR (ctest --show-only=json-v1).

    mpi_tests_yield.py CTEST BUILD_DIR
"""
import json
import subprocess
import sys


def main():
    ctest, build = sys.argv[1], sys.argv[2]
    listing = json.loads(subprocess.run([ctest, "--show-only=json-v1"], cwd=build, capture_output=True,
                                        check=True, text=True).stdout)
    checked, missing = 0, []
    for test in listing.get("tests", []):
        props = {p["name"]: p["value"] for p in test.get("properties", [])}
        if "mpi" not in (props.get("LABELS") or []):
            continue
        checked += 1
        env = props.get("ENVIRONMENT") or []
        if "OMPI_MCA_mpi_yield_when_idle=1" not in env:
            missing.append(test["name"])
    for name in missing:
        print("FAIL %s: no OMPI_MCA_mpi_yield_when_idle=1 in its ENVIRONMENT" % name)
    print("%d of %d mpi-labelled tests yield when idle" % (checked - len(missing), checked))
    return 1 if missing or checked == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
