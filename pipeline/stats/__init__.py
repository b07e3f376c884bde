"""Statistics of downfall directions (:mod:`.circular`) and locating a source from
falls (:mod:`.location`)."""
