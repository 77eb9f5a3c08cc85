"""docs/python.md shows the example script as it is."""

from conftest import REPO


def test_the_worked_example_in_the_docs_is_the_script():
    doc = (REPO / "docs" / "python.md").read_text()
    script = (REPO / "python" / "examples" / "golden_paper.py").read_text()
    assert f"```python\n{script}```" in doc


def test_the_klems_example_in_the_docs_runs_and_prints_its_output(tmp_path):
    """The "Klems matrices" example of docs/python.md, run in a scratch
    folder (it writes a file), prints what the page shows."""
    import subprocess
    import sys

    from conftest import SHARED

    doc = (REPO / "docs" / "python.md").read_text()
    section = doc[doc.index("## Klems matrices"):]
    code = section.split("```python\n", 1)[1].split("```", 1)[0]
    shown = section.split("Its output:\n\n```\n", 1)[1].split("```", 1)[0]
    code = code.replace('"../shared/', f'"{SHARED}/')
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout == shown.replace('"../shared/', f'"{SHARED}/')
    assert (tmp_path / "sa1_front.xml").is_file()
