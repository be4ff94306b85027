"""What the plugins share: the element reader, the plugin interface, the sample types."""
