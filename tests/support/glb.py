"""Writes a glTF binary: a JSON chunk and one BIN chunk, both padded to 4 bytes
as the format asks (the JSON with spaces, the binary with zeros)."""
import json
import struct


def write_glb(path, doc, binary):
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    binary = bytes(binary) + b"\0" * (-len(binary) % 4)
    with open(path, "wb") as f:
        f.write(struct.pack("<3I", 0x46546C67, 2, 12 + 8 + len(text) + 8 + len(binary)))
        f.write(struct.pack("<2I", len(text), 0x4E4F534A) + text)
        f.write(struct.pack("<2I", len(binary), 0x004E4942) + binary)
