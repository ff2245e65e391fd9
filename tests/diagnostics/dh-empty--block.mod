robot planar {
    dh {   # expect: error[dh-empty] the DH table has no rows
    }
}
