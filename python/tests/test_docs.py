"""docs/python.md shows the example script as it is."""

from conftest import REPO


def test_the_worked_example_in_the_docs_is_the_script():
    doc = (REPO / "docs" / "python.md").read_text()
    script = (REPO / "python" / "examples" / "golden_paper.py").read_text()
    assert f"```python\n{script}```" in doc
