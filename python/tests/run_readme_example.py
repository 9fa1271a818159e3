"""Runs the README's Python example verbatim (the ```python block after the
line starting "Python (`import icd`"), from the repository root: the README
shows code that runs as shown. Fails when the block is missing."""
import pathlib
import sys

root = pathlib.Path(__file__).resolve().parents[2]
text = (root / "README.md").read_text(encoding="utf-8")
marker = text.find("\nPython (`import icd`")
if marker < 0:
    sys.exit("README.md: no 'Python (`import icd`' paragraph")
start = text.find("```python\n", marker)
end = text.find("```\n", start + 10)
if start < 0 or end < 0:
    sys.exit("README.md: no ```python block after the Python paragraph")
code = text[start + len("```python\n"):end]
before = {p.name for p in root.iterdir()}
exec(compile(code, "README.md (Python example)", "exec"), {"__name__": "__readme__"})
# Nothing written into the repository root (a default folder once became ".").
stray = sorted({p.name for p in root.iterdir()} - before)
if stray:
    sys.exit("README example wrote into the repository root: " + ", ".join(stray))
print("README Python example ran:", len(code.splitlines()), "lines")
