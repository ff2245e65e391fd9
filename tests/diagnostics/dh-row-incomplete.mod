# Every DH row needs a, alpha and d (theta is optional). The incomplete row is dropped and the
# rest still converted: a one-unit arm, hence also last-variant and the approximation note.
robot planar {   # expect: note[dh-approximation]
    dh {
        row a=0.3 m, alpha=0deg, d=0 m   # expect: error[last-variant]
        row a=0.22 m, d=0 m   # expect: error[dh-row-incomplete]
    }
}
