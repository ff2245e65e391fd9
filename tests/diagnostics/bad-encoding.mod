# Saved as Latin-1 by an old editor: the degree sign below is byte 0xb0, not UTF-8.
robot farm {
    chain H1 - L4(port=45deg) - L1   # port twist 45°   # expect: error[bad-encoding] the file is not UTF-8 text (byte 0xb0)
}
