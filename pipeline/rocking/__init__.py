"""Rigid rectangular block (or cylinder) rocking in a plane: the reference the YADE model
is verified against.  Housner's constants and closed forms (:mod:`.housner`), his
equation integrated event by event (:mod:`.response`), one-sine pulses
(:mod:`.pulse`), many blocks under sampled ground accelerations at once
(:mod:`.sampled`) and recorded free-rocking decays read (:mod:`.decay`).  SI units;
angles in rad, x = East."""
