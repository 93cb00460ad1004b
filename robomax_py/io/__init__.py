"""Stage 1: the file boundary. YAML cell, robot and tool files (pydantic, degrees, mm) -> frozen
specs in SI units; the only code that knows file keys. Also atomic writes and cell variants."""
