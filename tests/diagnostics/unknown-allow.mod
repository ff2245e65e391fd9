# Only assembly rules can be silenced.
robot farm {
    chain H1 - L4(port=45deg) - L1
    allow first-variant, missing-unit   # expect: error[unknown-allow] 'missing-unit' cannot be allowed
}
