# Filled in as the part lands.
