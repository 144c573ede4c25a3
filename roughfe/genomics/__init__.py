"""Surface roughness genomics: genomes, chromosomes, sequencing (genomics I), macro/micro
roughness, the genome database and roughness design (genomics II). Thesis Chapters 3-4."""
