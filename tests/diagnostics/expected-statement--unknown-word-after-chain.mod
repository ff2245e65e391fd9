# corpus-xfail: parser._label calls match_examples without token_type_match_fallback=True, so any word after a chain takes the first same-state example's label (missing-dash) unless it is literally 'foo'
robot cellarm {
    chain H1 - L4(port=45deg) - L1
    obstacle shelf size (0.6, 0.4, 0.02) m at (0.3, 0, 0.25) m   # expect: error[expected-statement]
}
