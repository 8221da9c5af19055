"""Prints `drawn` when a PNG has a pixel that is not all zero, else `blank` (no image library
needed: the IDAT stream inflated, filter bytes left out)."""
import struct
import sys
import zlib

data = open(sys.argv[1], "rb").read()
width = struct.unpack(">I", data[16:20])[0]
stream, at = b"", 8
while at < len(data):
    length = struct.unpack(">I", data[at:at + 4])[0]
    if data[at + 4:at + 8] == b"IDAT":
        stream += data[at + 8:at + 8 + length]
    at += 12 + length
rows = zlib.decompress(stream)
stride = 1 + 4 * width
print("drawn" if any(rows[i] for i in range(len(rows)) if i % stride) else "blank")
