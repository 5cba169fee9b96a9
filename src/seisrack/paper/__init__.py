"""The reproduction of the reference paper (Degée & Denoël, ULiège): its closed-form sliding
block (§II), its three validation examples (§III) and its 2-bay rack (§IV, Table 2), with its
own Markdown report and checks against the published values (``seisrack paper``,
``seisrack validate``). Kept apart from the engineer's report (:mod:`seisrack.report`)."""
