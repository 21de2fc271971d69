"""The design vocabulary: HandDesign and its rules, designs from files, errors, the paper's data, model registries, input files."""
