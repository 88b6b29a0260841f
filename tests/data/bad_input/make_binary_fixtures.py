#!/usr/bin/env python3
"""Writes the binary fixtures of tests/data/bad_input/ (PNG masks, KITTI .bin clouds, binary PCD,
ONNX and SQLite-less raw files). The text fixtures are written by hand; run this from its folder
to regenerate the binary ones: python3 make_binary_fixtures.py"""
import os
import struct
import zlib


def png(path, width, height, pixels, depth=8):
    """A grey PNG; pixels row-major, one int per pixel."""
    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    raw = b""
    for v in range(height):
        row = pixels[v * width:(v + 1) * width]
        raw += b"\x00" + (bytes(row) if depth == 8 else b"".join(struct.pack(">H", p) for p in row))
    data = (b"\x89PNG\r\n\x1a\n" +
            chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, depth, 0, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    with open(path, "wb") as f:
        f.write(data)


def write(path, data):
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    with open(path, "wb") as f:
        f.write(data)


def floats(*values):
    return struct.pack("<%df" % len(values), *values)


# Masks: the image is 8 x 6 px (bad_input_test.cc).
inside = [255 if 2 <= u <= 5 and 1 <= v <= 4 else 0 for v in range(6) for u in range(8)]
png("masks/wrong_size_folder/0.png", 8, 6, inside)
png("masks/wrong_size_folder/1.png", 10, 6, [0] * 60)
write("masks/not_png_folder/0.png", b"this is not a PNG, it is text\n")
write("masks/empty_folder/metadata.csv", b"id,area\n")
png("masks/label_wrong_size.png", 6, 8, [1] * 48)
png("masks/label_all_zero.png", 8, 6, [0] * 48)
write("masks/truncated_label.png", open("masks/label_all_zero.png", "rb").read()[:40])

# KITTI .bin: float32 x y z intensity per point.
good = floats(1.0, 2.0, 0.5, 0.3, 4.0, -1.0, 0.2, 0.7)
write("kitti_bin/not_multiple_of_16.bin", good + floats(1.0))
write("kitti_bin/text_named_bin.bin", b"This is a text file, not a cloud!\nabcdefghijklmno\n"[:48])
write("kitti_bin/huge_coordinate.bin", good + floats(3.0, 1e30, 0.0, 0.1))

# Binary PCD whose data stops short of what the header promises.
header = ("VERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
          "WIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA binary\n").encode()
write("pcd/binary_truncated.pcd", header + good)
compressed = header.replace(b"DATA binary", b"DATA binary_compressed")
write("pcd/compressed_wrong_size.pcd", compressed + struct.pack("<II", 8, 40) + b"\x00" * 8)

# ONNX: the segmenter must refuse these naming the file.
write("onnx/empty.onnx", b"")
write("onnx/text.onnx", b"# not a network\nlayers: [conv, relu]\n")
write("onnx/garbage_bytes.onnx", bytes((i * 97 + 13) % 256 for i in range(512)))
src = os.path.join("..", "..", "..", "models", "segmentation", "yard_segmenter.onnx")
write("onnx/truncated.onnx", open(src, "rb").read()[:4096])

# SQLite demonstrations: an empty file and text named .sqlite.
write("demonstrations/empty.sqlite", b"")
write("demonstrations/text.sqlite", b"SQLite format 2\x00 but not really a database\n" * 4)

# More KITTI .bin: a PCD renamed .bin (its header decodes to absurd floats), a lone partial point.
write("kitti_bin/pcd_renamed.bin", open("pcd/short_ascii_row.pcd", "rb").read()[:64])
write("kitti_bin/one_partial_point.bin", floats(1.0, 2.0, 3.0)[:11])

# Image headers (identification/camera_lidar/image_header.h): dimensions are read before any
# decoding, so a bomb is refused from its first 24 bytes.
def png_header_only(width, height, first=b"IHDR", length=13):
    body = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + struct.pack(">I", length) + first + body +
            struct.pack(">I", zlib.crc32(first + body) & 0xFFFFFFFF))


# 20000 x 20000 px in 45 bytes (IHDR, IEND): cv::imread would allocate 400 MB (grey) or more.
write("image_header/png_bomb.png",
      png_header_only(20000, 20000) +
      struct.pack(">I", 0) + b"IEND" + struct.pack(">I", zlib.crc32(b"IEND") & 0xFFFFFFFF))
write("image_header/png_zero_width.png", png_header_only(0, 480))
write("image_header/png_truncated_ihdr.png", png_header_only(640, 480)[:20])
write("image_header/png_first_chunk_not_ihdr.png", png_header_only(640, 480, first=b"IDAT"))
write("image_header/empty.png", b"")
write("image_header/text_named_png.png", b"this is not an image, it is text\n")
# JPEG: SOI, an APP0 segment, then the scan (SOS) with no frame header before it.
app0 = b"\xff\xe0" + struct.pack(">H", 16) + b"JFIF\x00\x01\x01\x00\x00\x01\x00\x01\x00\x00"
write("image_header/jpeg_no_frame_header.jpg", b"\xff\xd8" + app0 + b"\xff\xda\x00\x08" + b"\x00" * 6)
# A segment whose length runs past the end of the file.
write("image_header/jpeg_segment_past_end.jpg", b"\xff\xd8\xff\xe1\x40\x00Exif\x00\x00")
# SOF0 with height 0 (the height would come later in a DNL marker).
write("image_header/jpeg_zero_height.jpg",
      b"\xff\xd8" + app0 + b"\xff\xc0" + struct.pack(">HBHHB", 11, 8, 0, 640, 1) + b"\x01\x11\x00")
# SOF2 (progressive) claiming 65000 x 65000 px.
write("image_header/jpeg_bomb.jpg",
      b"\xff\xd8" + app0 + b"\xff\xc2" + struct.pack(">HBHHB", 11, 8, 65000, 65000, 1) +
      b"\x01\x11\x00")
