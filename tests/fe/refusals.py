"""What every bad-input test of the FE command line checks: one line, exit 2, no traceback."""


def refused(result, *words):
    """``result`` (a CliRunner result) is a refusal in one line holding each of ``words``."""
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and "Traceback" not in result.output, result.output
    for word in words:
        assert word in lines[0], (word, lines[0])
