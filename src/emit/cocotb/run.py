"""Runs test_dynrt_processor.py on this folder's processor with cocotb's Python runner in
Icarus Verilog: python run.py [--build-dir DIR]. Exits non-zero when a frame differs from
golden<k>.hex; JUnit results in DIR/results.xml."""

import argparse
import os
import sys
from pathlib import Path

from cocotb_tools.runner import get_runner


def main():
    here = Path(__file__).resolve().parent
    top = here.parent
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--build-dir", default=str(top / "cocotb_build"))
    args = parser.parse_args()
    runner = get_runner("icarus")
    runner.build(
        sources=[top / "rtl" / "dynrt_processor.v"],
        hdl_toplevel="dynrt_processor",
        build_dir=args.build_dir,
        timescale=("1ns", "1ps"),
    )
    results = runner.test(
        hdl_toplevel="dynrt_processor",
        test_module="test_dynrt_processor",
        test_dir=str(here),
        build_dir=args.build_dir,
        extra_env={"DYNRT_DIR": str(top), "PYTHONPATH": str(here)},
    )
    from cocotb_tools.check_results import get_results

    total, failed = get_results(results)
    print(f"cocotb: {total - failed} passed, {failed} failed ({results})")
    sys.exit(1 if failed or total == 0 else 0)


if __name__ == "__main__":
    main()
