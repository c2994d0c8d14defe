"""The FMU's binaries carry what they need and the win64 one runs as the linux64 one does
(docs/fmu.md, "Platforms and what the binaries need").

- Each binary in the FMU needs no shared library beyond the platform's C runtime, libm and, on
  Linux, GNU OpenMP (`objdump -p`: NEEDED entries of the .so, imported DLLs of the DLL), and
  exports the FMI 2.0 functions only.
- The win64 binary is in the FMU whenever the build machine has the mingw-w64 cross compiler.
- Under Wine, the win64 DLL driven by tests/fmu/fmu_host.c (cross-compiled) gives the same outputs
  as the linux64 .so driven by the same host built for Linux, for 0.2 s of the Vajont case at
  dx = 0.03 m on two threads; each host also unloads the binary, loads it again and checks the
  second run repeats the first. Skipped where Wine (Debian's wine64) is not installed.
"""
import csv
import os
import re
import shutil
import subprocess
import zipfile

import pytest

import fmu_helpers as H

# linux64: glibc's C library and libm; libgomp.so.1 because Debian's libgomp.a is not
# position-independent code and cannot be linked into a shared object.
ALLOWED_LINUX = {"libc.so.6", "libm.so.6", "libgomp.so.1"}
# win64: the Windows kernel and the C runtime every mingw-w64 program uses (GNU OpenMP, libgcc and
# winpthreads are linked in).
ALLOWED_WIN = {"kernel32.dll", "msvcrt.dll"}
MINGW_CC = "x86_64-w64-mingw32-gcc-posix"
WINE = shutil.which("wine64") or next((p for p in ["/usr/lib/wine/wine64"] if os.path.exists(p)), None)


def _objdump(path):
    return subprocess.run(["objdump", "-p", str(path)], capture_output=True, text=True, check=True).stdout


def _binaries():
    d = H.unzipped()
    return {p: os.path.join(d, "binaries", p, "LandslideWave" + ext)
            for p, ext in [("linux64", ".so"), ("win64", ".dll")]}


def test_linux64_needs_only_libc_libm_and_gomp():
    info = _objdump(_binaries()["linux64"])
    needed = set(re.findall(r"^\s*NEEDED\s+(\S+)", info, re.M))
    assert needed and needed <= ALLOWED_LINUX, f"needs {sorted(needed - ALLOWED_LINUX)}"
    exported = subprocess.run(["nm", "-D", "--defined-only", _binaries()["linux64"]], capture_output=True,
                              text=True, check=True).stdout.split("\n")
    names = [line.split()[-1] for line in exported if line.strip()]
    assert names and all(n.startswith("fmi2") for n in names), [n for n in names if not n.startswith("fmi2")]


def test_win64_is_in_the_fmu_when_the_cross_compiler_is_there():
    with zipfile.ZipFile(H.fmu_path()) as z:
        have = "binaries/win64/LandslideWave.dll" in z.namelist()
    if not have and not shutil.which(MINGW_CC):
        pytest.skip(f"no {MINGW_CC} (Debian gcc-mingw-w64-x86-64-posix): the FMU is linux64 only")
    assert have, f"{MINGW_CC} is installed, but the FMU has no binaries/win64/LandslideWave.dll"


def test_win64_needs_only_kernel32_and_msvcrt():
    dll = _binaries()["win64"]
    if not os.path.exists(dll):
        pytest.skip("no win64 binary in the FMU")
    info = _objdump(dll)
    dlls = {d.lower() for d in re.findall(r"DLL Name:\s*(\S+)", info)}
    assert dlls and dlls <= ALLOWED_WIN, f"imports {sorted(dlls - ALLOWED_WIN)}"
    table = info.split("[Ordinal/Name Pointer] Table", 1)[1].split("\n\n", 1)[0]
    names = re.findall(r"\]\s+(\S+)", table)
    assert len(names) == 44 and all(n.startswith("fmi2") for n in names), names  # the FMI 2.0 functions


def _host_rows(text):
    rows = list(csv.reader(text.replace("\r\n", "\n").splitlines()))
    assert rows and rows[0][0] == "time" and len(rows) == 21, text[-2000:]  # 0.2 s every 0.01 s
    return rows


def test_win64_under_wine_gives_the_linux64_outputs(tmp_path):
    host_linux = H.BUILD / "fmu" / "fmu_host"
    host_win = H.BUILD / "fmu" / "win64" / "fmu" / "fmu_host.exe"
    if not os.path.exists(_binaries()["win64"]) or not host_win.exists():
        pytest.skip("no win64 binary or no win64 fmu_host.exe in the build")
    if not WINE:
        pytest.skip("no Wine (Debian package wine64)")
    args = ["0.2", "0.03", "2"]  # stop time [s], dx [m], threads
    d = H.unzipped()
    lin = subprocess.run([str(host_linux), d, *args], capture_output=True, text=True, timeout=600)
    assert lin.returncode == 0, lin.stderr
    env = {**os.environ, "WINEPREFIX": str(tmp_path / "wineprefix"), "WINEDEBUG": "-all"}
    subprocess.run([WINE, "wineboot", "-i"], env=env, capture_output=True, timeout=600)
    win = subprocess.run([WINE, str(host_win), "Z:" + d.replace("/", "\\"), *args], env=env, capture_output=True,
                         text=True, timeout=1200)
    assert win.returncode == 0, win.stderr[-3000:]
    a, b = _host_rows(lin.stdout), _host_rows(win.stdout)
    # Tolerance: none, the outputs printed with 17 significant digits are equal. Both binaries
    # are GCC 12 builds of the same C11 source (ISO C mode: no floating-point contraction) doing
    # IEEE-754 double arithmetic, in the same order whatever the thread count (docs/fmu.md);
    # they differ in the C runtime's maths functions (glibc, mingw-w64) and in the vector width
    # of the pair loops (the .so picks AVX2 or AVX-512 clones at run time, the DLL has baseline
    # x86-64 code). Measured equal; a difference appearing here is a platform difference to
    # explain, not noise to tolerate.
    assert a == b
